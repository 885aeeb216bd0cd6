// `shadowfilter coherent`: coherent shadow maps (methods.md sec. 5; Ritschel 2007; docs/coherent.md).
// build renders and compresses a stack of dual-depth maps around an object into a .csm file;
// info describes one.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "coherent_file.hpp"
#include "coherent_reference.hpp"
#include "coherent_stack.hpp"
#include "commands.hpp"
#include "output_file.hpp"
#include "progress.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

struct BuildArgs {
  std::string source, output, views = "32x32", ordering = "hilbert", far_plane = "sphere";
  std::string compress = "auto", device, renderer = "auto";
  int resolution = 128, depth_pair = 12, threads = 0;
  bool quiet = false;
};

struct InfoArgs {
  std::string file;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

// "TxP" -> rows and columns of the view grid.
void parse_views(const std::string& s, coherent::StackLayout& l) {
  int rows = 0, cols = 0;
  char x = 0, extra = 0;
  std::istringstream in(s);
  if (!(in >> rows >> x >> cols) || x != 'x' || (in >> extra))
    throw InputError("--views must be ROWSxCOLUMNS (e.g. 32x32), got '" + s + "'");
  l.views_theta = rows;
  l.views_phi = cols;
}

// The sizes a .csm holds, as one line (Table 1's columns: uncompressed, compressed, ratio).
std::string size_summary(const coherent::CompressedStack& c) {
  const double mib = 1024.0 * 1024.0;
  const double unc = double(c.layout.uncompressed_bytes()), comp = double(c.compressed_bytes());
  return std::to_string(c.layout.views_theta) + "x" + std::to_string(c.layout.views_phi) + " views (" +
         std::to_string(c.layout.views()) + "), M = " + std::to_string(c.layout.resolution) + ", " +
         coherent::ordering_name(c.layout.ordering) + ", depth pair " + std::to_string(uint32_t(c.layout.depth_pair)) +
         ", far plane " + coherent::far_plane_name(c.layout.far_plane) + ": " + std::to_string(c.segments.size()) +
         " segments (" + fixed(double(c.segments.size()) / double(c.layout.texels()), 1) +
         " per texel), uncompressed " + fixed(unc / mib, 1) + " MiB, compressed " + fixed(comp / mib, 2) +
         " MiB, ratio " + fixed(unc / comp, 1) + ":1";
}

int run_build(const BuildArgs& a) {
  io::check_outputs({a.output}, {a.source});
  coherent::StackLayout layout;
  parse_views(a.views, layout);
  layout.resolution = a.resolution;
  if (!coherent::parse_ordering(a.ordering, &layout.ordering))
    throw InputError("--ordering must be scanline, zigzag or hilbert, got '" + a.ordering + "'");
  if (a.depth_pair != 12 && a.depth_pair != 13) throw InputError("--depth-pair must be 12 or 13");
  layout.depth_pair = coherent::DepthPair(a.depth_pair);
  if (!coherent::parse_far_plane(a.far_plane, &layout.far_plane))
    throw InputError("--far-plane must be sphere or infinite, got '" + a.far_plane + "'");
  if (a.threads < 0 || a.threads > 1024) throw InputError("--threads must be in [0, 1024]");
  if (a.renderer != "auto" && a.renderer != "embree")
    throw InputError("--renderer must be auto or embree, got '" + a.renderer + "'");
  if (a.compress != "auto" && a.compress != "device" && a.compress != "host")
    throw InputError("--compress must be auto, device or host, got '" + a.compress + "'");
  // The device is chosen before the long render, so a bad --device fails at once. auto: the
  // kernel on a GPU; on a CPU device the host's pass, which costs about what the kernel does there
  // and saves copying the stack to the device (docs/coherent.md, "Compression").
  std::shared_ptr<Runtime> runtime = a.compress != "host" ? Runtime::create(a.device) : nullptr;
  if (a.compress == "auto" && runtime->info().type != "GPU") runtime.reset();
  coherent::validate(layout);
  // The uncompressed stack (z1 and z2, 2 bytes each) is held in memory while it is compressed.
  const double stack_bytes = 4.0 * double(layout.views()) * double(layout.texels());
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0.0 && stack_bytes > 0.75 * memory)
    throw InputError("the dual-depth stack of " + std::to_string(layout.views()) + " views of " +
                     std::to_string(layout.resolution) + "^2 texels needs " + fixed(stack_bytes / 1073741824.0, 1) +
                     " GiB, more than 3/4 of this machine's " + fixed(memory / 1073741824.0, 1) +
                     " GiB: fewer views or a smaller --res");
  const scene::SceneGeometry object = scene::load_coherent_object(a.source);
  scene::fit_bounding_sphere(object, layout);

  const auto t0 = std::chrono::steady_clock::now();
  coherent::DualDepthStack stack;
  {
    scene::Progress progress("rendering views", size_t(layout.views()), !a.quiet);
    stack = scene::render_stack(
        object, layout, a.threads, [&](size_t n) { progress.add(n); },
        a.renderer == "embree" ? scene::StackRenderer::Embree : scene::StackRenderer::Auto);
  }
  const double render_s = seconds_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  io::CoherentFile file;
  file.stack = runtime ? coherent::compress_on_device(*runtime, stack) : ref::coherent::compress(stack);
  const double compress_s = seconds_since(t1);
  file.source = a.source;
  io::write_coherent(a.output, file);
  if (!a.quiet)
    std::cout << "coherent build: " << a.output << ": " << size_summary(file.stack) << "; render " << fixed(render_s, 2)
              << " s, compress " << fixed(compress_s, 2) << " s, total " << fixed(render_s + compress_s, 2)
              << " s, compressed on " << (runtime ? runtime->info().device_name : std::string("the host")) << "\n";
  return 0;
}

int run_info(const InfoArgs& a) {
  const io::CoherentFile file = io::read_coherent(a.file);
  const coherent::StackLayout& l = file.stack.layout;
  std::cout << a.file << ": object '" << file.source << "', bounding sphere centre (" << l.center[0] << ", "
            << l.center[1] << ", " << l.center[2] << ") radius " << l.radius << "; " << size_summary(file.stack)
            << "\n";
  return 0;
}

}  // namespace

void add_coherent_command(CLI::App& app, CoherentCommands& out) {
  CLI::App* c = app.add_subcommand("coherent", "Coherent shadow maps: many depth maps around an object, compressed");
  c->require_subcommand(1);
  out.app = c;

  auto build = std::make_shared<BuildArgs>();
  CLI::App* b =
      c->add_subcommand("build", "Render the dual-depth maps of an object and compress them into a .csm file");
  b->add_option("object", build->source,
                "Mesh file (OBJ, PLY, OFF, STL) or built-in object (sphere, box, a scene name)")
      ->required();
  b->add_option("-o,--out", build->output, "Output .csm file (written atomically)")->required();
  b->add_option("--views", build->views, "Lat-long grid of view directions, ROWSxCOLUMNS")->capture_default_str();
  b->add_option("--res", build->resolution, "Texels per side of each depth map (M)")->capture_default_str();
  b->add_option("--ordering", build->ordering, "Enumeration of the views: scanline|zigzag|hilbert")
      ->capture_default_str();
  b->add_option("--depth-pair", build->depth_pair,
                "Surfaces the stored depth separates: 12 (first, second) or 13 (first, third: closed meshes)")
      ->capture_default_str();
  b->add_option("--far-plane", build->far_plane,
                "A missing upper surface: sphere (the bounding sphere's exit) or infinite")
      ->capture_default_str();
  b->add_option("--renderer", build->renderer,
                "How views are rendered: auto (meshes rasterised, analytic spheres ray-cast) or embree (every view "
                "ray-cast; the same depths at texel centres)")
      ->capture_default_str();
  b->add_option("--threads", build->threads, "Rendering threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  b->add_option("--compress", build->compress,
                "Where the segments are fitted: device (OpenCL kernel), host (the scalar reference; same bytes) or "
                "auto (device on a GPU, else host)")
      ->capture_default_str();
  b->add_option("--device", build->device, "OpenCL device of --compress device (as filter's --device)");
  b->add_flag("-q,--quiet", build->quiet, "No progress bar or summary");
  out.subcommands.push_back({b, [build] { return run_build(*build); }});

  auto info = std::make_shared<InfoArgs>();
  CLI::App* i = c->add_subcommand("info", "Describe a .csm file: layout, object, sizes and compression ratio");
  i->add_option("file", info->file, ".csm file")->required();
  out.subcommands.push_back({i, [info] { return run_info(*info); }});

  add_coherent_render_commands(*c, out);
}

int run_coherent(const CoherentCommands& commands) {
  for (const auto& [app, run] : commands.subcommands)
    if (app->parsed()) return run();
  return 1;
}

}  // namespace sf::cli

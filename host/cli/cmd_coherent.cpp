// `shadowfilter coherent`: coherent shadow maps (methods.md sec. 5; Ritschel 2007; docs/coherent.md).
// build renders and compresses a stack of dual-depth maps around an object into a .csm file (or,
// with --shard K/N, renders one contiguous range of its views into a part); merge compresses the
// parts into the .csm one build writes; info describes one.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "coherent_file.hpp"
#include "coherent_reference.hpp"
#include "coherent_stack.hpp"
#include "mesh_file.hpp"
#include "view_raster_device.hpp"
#include "commands.hpp"
#include "frame_list.hpp"
#include "output_file.hpp"
#include "progress.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

struct BuildArgs {
  std::string source, output, views = "32x32", ordering = "hilbert", far_plane = "sphere";
  std::string compress = "auto", device, renderer = "auto", shard;
  int resolution = 128, depth_pair = 12, threads = 0;
  int chunk_views = 0;  // views per chunk of a streamed build; 0: 256 MiB of maps
  bool quiet = false;
  const CLI::Option* compress_option = nullptr;  // given: with --shard, refused (the merge compresses)
  const CLI::Option* device_option = nullptr;
  // A fixed local light's depth cube maps instead of the distant views: its rectangle and grid.
  std::vector<double> local_light;
  std::string local_light_mesh, light_samples = "8x8";
  // Options of the distant views, refused with --local-light when given.
  std::vector<const CLI::Option*> distant_options;
};

struct MergeArgs {
  std::vector<std::string> parts;
  std::string output, compress = "auto", device;
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
std::string size_summary(const coherent::CompressedStack& c, const std::optional<coherent::LocalLight>& local = {}) {
  const double mib = 1024.0 * 1024.0;
  const double unc = double(c.layout.uncompressed_bytes()), comp = double(c.compressed_bytes());
  if (local)
    return "local light, " + std::to_string(local->samples_a) + "x" + std::to_string(local->samples_b) +
           " sampling points (" + std::to_string(local->count()) + " cube maps, " + std::to_string(c.layout.views()) +
           " maps), M = " + std::to_string(c.layout.resolution) + ", " + coherent::ordering_name(local->ordering) +
           ", far " + fixed(local->far, 4) + ": " + std::to_string(c.segment_count()) + " segments (" +
           fixed(double(c.segment_count()) / double(c.layout.texels()), 1) + " per texel), uncompressed " +
           fixed(unc / mib, 1) + " MiB, compressed " + fixed(comp / mib, 2) + " MiB, ratio " + fixed(unc / comp, 1) +
           ":1";
  return std::to_string(c.layout.views_theta) + "x" + std::to_string(c.layout.views_phi) + " views (" +
         std::to_string(c.layout.views()) + "), M = " + std::to_string(c.layout.resolution) + ", " +
         coherent::ordering_name(c.layout.ordering) + ", depth pair " + std::to_string(uint32_t(c.layout.depth_pair)) +
         ", far plane " + coherent::far_plane_name(c.layout.far_plane) + ": " + std::to_string(c.segment_count()) +
         " segments (" + fixed(double(c.segment_count()) / double(c.layout.texels()), 1) +
         " per texel), uncompressed " + fixed(unc / mib, 1) + " MiB, compressed " + fixed(comp / mib, 2) +
         " MiB, ratio " + fixed(unc / comp, 1) + ":1";
}

// The device that compresses (--compress, --device), chosen before the long render so that a bad
// --device fails at once; null for the host. auto: the kernel on a GPU; on a CPU device the
// host's pass, which costs about what the kernel does there and saves copying the stack to the
// device (docs/coherent.md, "Compression").
std::shared_ptr<Runtime> compression_runtime(const std::string& compress, const std::string& device) {
  if (compress != "auto" && compress != "device" && compress != "host")
    throw InputError("--compress must be auto, device or host, got '" + compress + "'");
  std::shared_ptr<Runtime> runtime = compress != "host" ? Runtime::create(device) : nullptr;
  if (compress == "auto" && runtime->info().type != "GPU") runtime.reset();
  return runtime;
}

// The uncompressed maps (z1 and z2, 2 bytes each) are held in memory while they are written or
// compressed: refused when they would take more than 3/4 of the machine's memory.
void check_memory(const coherent::StackLayout& layout, size_t views) {
  const double stack_bytes = 4.0 * double(views) * double(layout.texels());
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0.0 && stack_bytes > 0.75 * memory)
    throw InputError("the dual-depth stack of " + std::to_string(views) + " views of " +
                     std::to_string(layout.resolution) + "^2 texels needs " + fixed(stack_bytes / 1073741824.0, 1) +
                     " GiB, more than 3/4 of this machine's " + fixed(memory / 1073741824.0, 1) +
                     " GiB: fewer views, a smaller --res or --shard K/N");
}

// Writes the .csm, with the summary line of `command` unless quiet (before_s: the rendering or
// reading before the fit; fit_s: the fit's own time).
void write_compressed(io::CoherentFile file, const std::shared_ptr<Runtime>& runtime, const std::string& output,
                      const std::string& command, double before_s, double fit_s, bool quiet) {
  io::write_coherent(output, file);
  if (!quiet)
    std::cout << "coherent " << command << ": " << output << ": " << size_summary(file.stack, file.local) << "; "
              << (command == "build" ? "render " : "read ") << fixed(before_s, 2) << " s, compress " << fixed(fit_s, 2)
              << " s, total " << fixed(before_s + fit_s, 2) << " s, compressed on "
              << (runtime ? runtime->info().device_name : std::string("the host, streamed")) << "\n";
}

// Views per chunk of a streamed build: 256 MiB of z1 and z2 (4096 views at M = 128), so that the
// build's memory is a chunk and the segments, not the stack.
uint32_t chunk_views(const coherent::StackLayout& layout) {
  const size_t per_view = 4 * layout.texels();
  return uint32_t(std::clamp<size_t>((size_t(256) << 20) / per_view, 1, size_t(layout.views())));
}

// `coherent build --local-light`: the depth cube maps of a fixed light (Ritschel 2007 sec. 3.3,
// 4.2) around the object, ray-cast with Embree from every sampling point, compressed as one stack
// of 6 N maps (docs/coherent.md, "Local lights").
int run_build_local(const BuildArgs& a) {
  for (const CLI::Option* o : a.distant_options)
    if (o->count() > 0)
      throw InputError(o->get_name() + " is an option of the distant views; --local-light builds depth cube maps");
  if (!a.local_light.empty() && !a.local_light_mesh.empty())
    throw InputError("--local-light and --local-light-mesh: one light a build");
  coherent::StackLayout grid;
  parse_views(a.light_samples, grid);
  coherent::LocalLight light;
  if (!a.local_light_mesh.empty()) {
    // The mesh's own coordinates: the object's frame as `coherent info` shows it.
    if (long(grid.views_theta) * grid.views_phi > coherent::kMaxLightSamples || grid.views_theta < 1 ||
        grid.views_phi < 1)
      throw InputError("--light-samples: 1 to " + std::to_string(coherent::kMaxLightSamples) + " sampling points");
    light = scene::mesh_light(scene::read_mesh_file(a.local_light_mesh), grid.views_theta * grid.views_phi);
  } else {
    light.corner = {a.local_light[0], a.local_light[1], a.local_light[2]};
    light.edge_a = {a.local_light[3], a.local_light[4], a.local_light[5]};
    light.edge_b = {a.local_light[6], a.local_light[7], a.local_light[8]};
    light.samples_a = grid.views_phi;
    light.samples_b = grid.views_theta;
    if (!coherent::parse_ordering(a.ordering, &light.ordering))
      throw InputError("--ordering must be scanline, zigzag or hilbert, got '" + a.ordering + "'");
  }
  if (a.resolution < 1 || a.resolution > 4096) throw InputError("--res must be in [1, 4096]");
  if (a.threads < 0 || a.threads > 1024) throw InputError("--threads must be in [0, 1024]");
  coherent::validate(light);
  std::shared_ptr<Runtime> runtime = compression_runtime(a.compress, a.device);
  const scene::SceneGeometry object = scene::load_coherent_object(a.source);
  const coherent::StackLayout layout = scene::fit_local_light(object, light, a.resolution);
  // Held at once: the whole stack for the device's fit; a chunk of maps for the host's (streamed,
  // in sequence order: the same bytes).
  const uint32_t chunk = runtime ? uint32_t(layout.views()) : chunk_views(layout);
  check_memory(layout, chunk);
  std::optional<scene::Progress> progress;
  progress.emplace("rendering cube maps", size_t(layout.views()), !a.quiet);
  double render_s = 0.0, fit_s = 0.0;
  io::CoherentFile file;
  file.source = a.source;
  file.local = light;
  ref::coherent::StreamingFit fit(layout);
  for (uint32_t first = 0; first < uint32_t(layout.views()); first += chunk) {
    const auto t0 = std::chrono::steady_clock::now();
    scene::StackPart part =
        scene::render_cube_stack_part(object, light, layout, {first, std::min(uint32_t(layout.views()), first + chunk)},
                                      a.threads, [&](size_t n) { progress->add(n); });
    render_s += seconds_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    if (runtime)
      file.stack = coherent::compress_on_device(*runtime, {layout, std::move(part.z1), std::move(part.z2)});
    else
      fit.add(part.z1.data(), part.z2.data(), part.range.count());
    fit_s += seconds_since(t1);
  }
  progress.reset();
  const auto t1 = std::chrono::steady_clock::now();
  if (!runtime) file.stack = fit.finish();
  fit_s += seconds_since(t1);
  write_compressed(std::move(file), runtime, a.output, "build", render_s, fit_s, a.quiet);
  return 0;
}

int run_build(const BuildArgs& a) {
  io::check_outputs({a.output}, {a.source, a.local_light_mesh});
  if (!a.local_light.empty() || !a.local_light_mesh.empty()) return run_build_local(a);
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
  if (a.renderer != "auto" && a.renderer != "embree" && a.renderer != "device")
    throw InputError("--renderer must be auto, embree or device, got '" + a.renderer + "'");
  const bool sharded = !a.shard.empty();
  if (sharded && a.renderer == "device")
    throw InputError("--renderer device renders the whole stack on one device; --shard renders a part on the host");
  if (sharded && ((a.compress_option && a.compress_option->count()) || (a.device_option && a.device_option->count())))
    throw InputError("--compress and --device are for the compression: with --shard, give them to coherent merge");
  std::shared_ptr<Runtime> runtime = sharded ? nullptr : compression_runtime(a.compress, a.device);
  coherent::validate(layout);
  scene::ViewRange range{0, uint32_t(layout.views())};
  if (sharded) {
    const Shard shard = parse_shard(a.shard);
    if (shard.count > size_t(layout.views()))
      throw InputError("--shard " + a.shard + ": more parts than the " + std::to_string(layout.views()) + " views");
    range = scene::shard_views(layout, shard.index, shard.count);
  }
  // Held at once: a part's maps; the whole stack for the device's fit; a chunk for the host's.
  if (a.chunk_views < 0) throw InputError("--chunk-views must be >= 0 (0: 256 MiB of maps)");
  const uint32_t chunk = sharded || runtime  ? range.count()
                         : a.chunk_views > 0 ? uint32_t(std::min(a.chunk_views, layout.views()))
                                             : chunk_views(layout);
  check_memory(layout, chunk);
  const scene::SceneGeometry object = scene::load_coherent_object(a.source);
  scene::fit_bounding_sphere(object, layout);
  const scene::StackRenderer renderer =
      a.renderer == "embree" ? scene::StackRenderer::Embree : scene::StackRenderer::Auto;

  std::optional<scene::Progress> progress;  // reset when the views are rendered: the bar ends its line
  progress.emplace("rendering views", size_t(range.count()), !a.quiet);
  auto render = [&](scene::ViewRange views) {
    return scene::render_stack_part(
        object, layout, views, a.threads, [&](size_t n) { progress->add(n); }, renderer);
  };
  double render_s = 0.0, fit_s = 0.0;
  io::CoherentFile file;
  file.source = a.source;
  if (a.renderer == "device") {
    // The views rasterised on the device (the host renderer's bytes); with device compression
    // the maps never leave it, else they are read back and fitted on the host.
    progress.reset();
    check_memory(layout, size_t(layout.views()));
    const std::shared_ptr<Runtime> device = runtime ? runtime : Runtime::create(a.device);
    scene::DeviceRasterStats stats;
    const coherent::DeviceDualDepth maps = scene::render_stack_on_device(*device, object, layout, &stats);
    render_s = stats.seconds;
    const auto t1 = std::chrono::steady_clock::now();
    if (runtime) {
      file.stack = coherent::download(*runtime, coherent::compress_on_device(*runtime, maps));
    } else {
      const size_t values = size_t(layout.views()) * layout.texels();
      std::vector<uint16_t> z1(values), z2(values);
      device->queue().enqueueReadBuffer(maps.z1, CL_TRUE, 0, values * sizeof(uint16_t), z1.data());
      device->queue().enqueueReadBuffer(maps.z2, CL_TRUE, 0, values * sizeof(uint16_t), z2.data());
      ref::coherent::StreamingFit fit(layout);
      fit.add(z1.data(), z2.data(), uint32_t(layout.views()));
      file.stack = fit.finish();
    }
    fit_s = seconds_since(t1);
    if (!a.quiet && stats.host_views)
      std::cout << "coherent build: " << stats.host_views << " of " << layout.views()
                << " views had texels of more crossings than the device's lists and were rendered on the host\n";
  } else if (sharded || runtime) {
    const auto t0 = std::chrono::steady_clock::now();
    scene::StackPart part = render(range);
    render_s = seconds_since(t0);
    progress.reset();
    if (sharded) {
      io::write_coherent_part(a.output,
                              {layout, a.source, range.first, range.end, std::move(part.z1), std::move(part.z2)});
      if (!a.quiet)
        std::cout << "coherent build: " << a.output << ": part " << a.shard << ", views " << range.first << ".."
                  << range.end << " of " << layout.views() << "; render " << fixed(render_s, 2)
                  << " s (coherent merge compresses the parts)\n";
      return 0;
    }
    const auto t1 = std::chrono::steady_clock::now();
    file.stack = coherent::compress_on_device(*runtime, {layout, std::move(part.z1), std::move(part.z2)});
    fit_s = seconds_since(t1);
  } else {
    // Streamed: each chunk of views is rendered, fitted and dropped (the same bytes as the whole
    // stack fitted at once: StreamingFit).
    ref::coherent::StreamingFit fit(layout);
    for (uint32_t first = 0; first < range.end; first += chunk) {
      const auto t0 = std::chrono::steady_clock::now();
      const scene::StackPart part = render({first, std::min(range.end, first + chunk)});
      const auto t1 = std::chrono::steady_clock::now();
      fit.add(part.z1.data(), part.z2.data(), part.range.count());
      render_s += std::chrono::duration<double>(t1 - t0).count();
      fit_s += seconds_since(t1);
    }
    progress.reset();
    const auto t2 = std::chrono::steady_clock::now();
    file.stack = fit.finish();
    fit_s += seconds_since(t2);
  }
  write_compressed(std::move(file), runtime, a.output, "build", render_s, fit_s, a.quiet);
  return 0;
}

bool same_layout(const coherent::StackLayout& a, const coherent::StackLayout& b) {
  return a.views_theta == b.views_theta && a.views_phi == b.views_phi && a.resolution == b.resolution &&
         a.ordering == b.ordering && a.depth_pair == b.depth_pair && a.far_plane == b.far_plane &&
         a.center[0] == b.center[0] && a.center[1] == b.center[1] && a.center[2] == b.center[2] && a.radius == b.radius;
}

// The parts of one stack (one layout and object, every view in exactly one part) into the .csm
// that the unsharded build writes, byte for byte. On the host the parts are read twice, checked,
// then fitted in sequence order one at a time (memory: one part); the device's fit takes the
// whole stack, assembled as the parts are checked.
int run_merge(const MergeArgs& a) {
  io::check_outputs({a.output}, a.parts);
  const std::shared_ptr<Runtime> runtime = compression_runtime(a.compress, a.device);
  const auto t0 = std::chrono::steady_clock::now();
  coherent::StackLayout layout;
  std::string source;
  coherent::DualDepthStack stack;                  // the device's fit only
  std::vector<int> owner;                          // the part that holds each view
  std::vector<std::pair<uint32_t, size_t>> order;  // (first view, part) for the host's fit
  for (size_t k = 0; k < a.parts.size(); ++k) {
    io::CoherentPart part = io::read_coherent_part(a.parts[k]);
    if (k == 0) {  // the first part gives the layout and object; the others are checked against them
      layout = part.layout;
      source = part.source;
      owner.assign(size_t(layout.views()), -1);
      check_memory(layout, runtime ? size_t(layout.views()) : size_t(part.end - part.first));
      if (runtime) {
        const size_t values = size_t(layout.views()) * layout.texels();
        stack = {layout, std::vector<uint16_t>(values, coherent::kNoSurface),
                 std::vector<uint16_t>(values, coherent::kNoSurface)};
      }
    } else if (!same_layout(part.layout, layout) || part.source != source) {
      throw InputError("'" + a.parts[k] + "' is a part of another stack than '" + a.parts.front() +
                       "' (its layout or object differs)");
    }
    for (uint32_t v = part.first; v < part.end; ++v) {
      if (owner[v] >= 0)
        throw InputError("'" + a.parts[k] + "' and '" + a.parts[size_t(owner[v])] + "' both hold view " +
                         std::to_string(v) + " (give each part once)");
      owner[v] = int(k);
    }
    order.emplace_back(part.first, k);
    if (runtime) {
      const size_t at = size_t(part.first) * layout.texels();
      std::copy(part.z1.begin(), part.z1.end(), stack.z1.begin() + long(at));
      std::copy(part.z2.begin(), part.z2.end(), stack.z2.begin() + long(at));
    }
  }
  for (size_t v = 0; v < owner.size(); ++v)
    if (owner[v] < 0) {
      size_t end = v;
      while (end < owner.size() && owner[end] < 0) ++end;
      throw InputError("views " + std::to_string(v) + ".." + std::to_string(end) + " of " +
                       std::to_string(layout.views()) + " are in no part (a shard's output is missing)");
    }
  io::CoherentFile file;
  file.source = source;
  double read_s = seconds_since(t0), fit_s = 0.0;
  if (runtime) {
    const auto t1 = std::chrono::steady_clock::now();
    file.stack = coherent::compress_on_device(*runtime, stack);
    fit_s = seconds_since(t1);
  } else {
    std::sort(order.begin(), order.end());
    ref::coherent::StreamingFit fit(layout);
    for (const auto& [first, k] : order) {
      const auto t1 = std::chrono::steady_clock::now();
      const io::CoherentPart part = io::read_coherent_part(a.parts[k]);
      if (part.first != first || !same_layout(part.layout, layout) || part.source != source)
        throw InputError("'" + a.parts[k] + "' changed while the merge read it");
      const auto t2 = std::chrono::steady_clock::now();
      fit.add(part.z1.data(), part.z2.data(), part.end - part.first);
      read_s += std::chrono::duration<double>(t2 - t1).count();
      fit_s += seconds_since(t2);
    }
    const auto t3 = std::chrono::steady_clock::now();
    file.stack = fit.finish();
    fit_s += seconds_since(t3);
  }
  write_compressed(std::move(file), runtime, a.output, "merge", read_s, fit_s, a.quiet);
  return 0;
}

int run_info(const InfoArgs& a) {
  const io::CoherentFile file = io::read_coherent(a.file);
  const coherent::StackLayout& l = file.stack.layout;
  std::cout << a.file << ": object '" << file.source << "', bounding sphere centre (" << l.center[0] << ", "
            << l.center[1] << ", " << l.center[2] << ") radius " << l.radius << "; "
            << size_summary(file.stack, file.local) << "\n";
  if (file.local && file.local->is_mesh()) {
    std::cout << "  mesh light: " << file.local->count() << " sampling points, area " << file.local->area << "\n";
  } else if (file.local) {
    const coherent::LocalLight& g = *file.local;
    std::cout << "  light: corner (" << g.corner.x << ", " << g.corner.y << ", " << g.corner.z << "), edge a ("
              << g.edge_a.x << ", " << g.edge_a.y << ", " << g.edge_a.z << "), edge b (" << g.edge_b.x << ", "
              << g.edge_b.y << ", " << g.edge_b.z << ")\n";
  }
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
  build->distant_options.push_back(
      b->add_option("--views", build->views, "Lat-long grid of view directions, ROWSxCOLUMNS")->capture_default_str());
  b->add_option("--res", build->resolution, "Texels per side of each depth map (M)")->capture_default_str();
  b->add_option("--ordering", build->ordering, "Enumeration of the views: scanline|zigzag|hilbert")
      ->capture_default_str();
  build->distant_options.push_back(
      b->add_option("--depth-pair", build->depth_pair,
                    "Surfaces the stored depth separates: 12 (first, second) or 13 (first, third: closed meshes)")
          ->capture_default_str());
  build->distant_options.push_back(
      b->add_option("--far-plane", build->far_plane,
                    "A missing upper surface: sphere (the bounding sphere's exit) or infinite")
          ->capture_default_str());
  b->add_option("--local-light", build->local_light,
                "Depth cube maps of a fixed local light instead of the distant views: a rectangle, corner, edge a, "
                "edge b (x y z each; a segment: edge b 0 0 0 with --light-samples Nx1)")
      ->expected(9);
  b->add_option("--local-light-mesh", build->local_light_mesh,
                "Depth cube maps of a fixed mesh light (OBJ, PLY, OFF, STL in the object's frame, as coherent info "
                "shows it): A B sampling points stratified by area over its triangles");
  b->add_option("--light-samples", build->light_samples,
                "The local light's sampling points, AxB across edge a and edge b (a cube map each; a mesh light: "
                "A B points)")
      ->capture_default_str();
  build->distant_options.push_back(
      b->add_option("--renderer", build->renderer,
                    "How views are rendered: auto (meshes rasterised, analytic spheres ray-cast), embree (every view "
                    "ray-cast; the same depths at texel centres) or device (meshes rasterised on the OpenCL device: "
                    "auto's bytes; needs cl_khr_fp64)")
          ->capture_default_str());
  b->add_option("--threads", build->threads, "Rendering threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  const char* const compress_help =
      "Where the segments are fitted: device (OpenCL kernel), host (the scalar reference; same bytes) or auto "
      "(device on a GPU, else host)";
  build->compress_option = b->add_option("--compress", build->compress, compress_help)->capture_default_str();
  build->device_option =
      b->add_option("--device", build->device, "OpenCL device of --compress device (as filter's --device)");
  build->distant_options.push_back(
      b->add_option("--chunk-views", build->chunk_views,
                    "Views rendered and fitted at a time when the host compresses (the build holds one chunk, not the "
                    "stack; 0: 256 MiB of maps)")
          ->capture_default_str());
  build->distant_options.push_back(
      b->add_option("--shard", build->shard,
                    "Render part K of N, views floor((K-1)V/N) .. floor(KV/N) of the sequence, into a stack part "
                    "(-o, .csmpart) that coherent merge compresses with the other parts")
          ->type_name("K/N"));
  b->add_flag("-q,--quiet", build->quiet, "No progress bar or summary");
  out.subcommands.push_back({b, [build] { return run_build(*build); }});

  auto merge = std::make_shared<MergeArgs>();
  CLI::App* g = c->add_subcommand(
      "merge", "Compress the parts of a sharded build (coherent build --shard K/N) into the .csm one build writes");
  g->add_option("parts", merge->parts, "The stack parts, every view in exactly one (any order)")->required();
  g->add_option("-o,--out", merge->output, "Output .csm file (written atomically)")->required();
  g->add_option("--compress", merge->compress, compress_help)->capture_default_str();
  g->add_option("--device", merge->device, "OpenCL device of --compress device (as filter's --device)");
  g->add_flag("-q,--quiet", merge->quiet, "No summary");
  g->footer(
      "Example (4 processes, any scheduler; docs/scale.md):\n"
      "  shadowfilter coherent build bunny.off -o p$K.csmpart --shard $K/4\n"
      "  shadowfilter coherent merge p?.csmpart -o bunny.csm");
  out.subcommands.push_back({g, [merge] { return run_merge(*merge); }});

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

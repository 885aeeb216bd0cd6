// `shadowfilter coherent render` and `coherent sky` (docs/coherent_render.md):
// direct lighting of a .csm file's object by an environment map and area lights, the visibility
// from the compressed stack on the device (or from Embree occlusion rays with --reference
// embree), and the synthetic sky that the repository's data/envmaps/sky.exr was written with.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "coherent_file.hpp"
#include "coherent_render.hpp"
#include "coherent_stack.hpp"
#include "commands.hpp"
#include "output_file.hpp"
#include "envmap.hpp"
#include "image_io.hpp"
#include "ray_tracer.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {
namespace {

struct RenderArgs {
  std::string file, envmap, output, filter = "nearest", reference, mesh, device;
  int samples = 16, width = 512, height = 512, threads = 0;
  unsigned seed = 1;
  std::vector<double> camera_pos, camera_look, albedo{0.8, 0.8, 0.8}, specular{0.0, 0.0, 0.0};
  double camera_fov = 40.0, shininess = 32.0, time_budget = 0.0;
  int passes = 1;
  CLI::Option* passes_option = nullptr;  // not given: 1 pass, or as many as --time-budget allows
  std::vector<std::vector<double>> area_lights;
  bool preview = false, quiet = false;
};

struct SkyArgs {
  std::string output;
  scene::SkyOptions options;
};

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

scene::Vec3 vec(const std::vector<double>& v, size_t at) { return {v[at], v[at + 1], v[at + 2]}; }

// The preview: 1 - exp(-x) per channel (highlights roll off instead of clipping), then the sRGB
// curve, so the 16-bit PNG looks right in an ordinary viewer.
HostImage tone_mapped(const HostImage& linear) {
  HostImage out = linear;
  out.channel_formats.clear();
  for (float& v : out.data) {
    const double x = 1.0 - std::exp(-std::max(0.0, double(v)));
    v = float(x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055);
  }
  return out;
}

int run_render(const RenderArgs& a) {
  // Options first: nothing is read or rendered for a command line that cannot succeed.
  if (a.samples < 1 || a.samples > scene::kMaxSamples)
    throw InputError("--samples must be in [1, " + std::to_string(scene::kMaxSamples) + "], got " +
                     std::to_string(a.samples));
  if (a.width < 1 || a.height < 1 || a.width > 8192 || a.height > 8192)
    throw InputError("--width and --height must be in [1, 8192]");
  if (!(a.camera_fov > 0.0 && a.camera_fov < 180.0)) throw InputError("--camera-fov must be in (0, 180) degrees");
  if (a.threads < 0) throw InputError("--threads must be >= 0");
  if (a.filter != "nearest" && a.filter != "pcf" && a.filter != "roulette")
    throw InputError("--filter must be nearest, pcf or roulette, got '" + a.filter + "'");
  if (a.filter != "nearest" && a.reference == "embree")
    throw InputError("--filter " + a.filter + " is a coherent-map lookup; --reference embree has none");
  if (!a.reference.empty() && a.reference != "embree")
    throw InputError("--reference must be embree, got '" + a.reference + "'");
  for (int c = 0; c < 3; ++c) {
    if (!(a.albedo[c] >= 0.0 && a.albedo[c] <= 1.0)) throw InputError("--albedo must be within [0, 1]");
    if (!(a.specular[c] >= 0.0 && a.specular[c] <= 1.0)) throw InputError("--specular must be within [0, 1]");
    // The modified Phong BRDF reflects at most albedo + specular: more would create energy.
    if (!(a.albedo[c] + a.specular[c] <= 1.0))
      throw InputError("--albedo + --specular must be <= 1 in every channel (energy conservation)");
  }
  for (const auto& l : a.area_lights)
    if (l.size() != 10 && l.size() != 12)
      throw InputError("--area-light takes corner, edge a, edge b (3 numbers each) and a radiance (1 or 3)");
  const std::string preview = a.preview ? io::preview_path(a.output) : std::string();
  io::check_outputs({a.output, preview}, {a.file, a.envmap, a.mesh});

  const io::CoherentFile file = io::read_coherent(a.file);
  const coherent::StackLayout& layout = file.stack.layout;
  const scene::Vec3 center{layout.center[0], layout.center[1], layout.center[2]};
  const scene::EnvMap env = scene::load_envmap(a.envmap);
  scene::RenderSettings settings;
  settings.samples = a.samples;
  settings.seed = a.seed;
  settings.threads = a.threads;
  settings.filter = a.filter == "pcf"        ? scene::VisibilityFilter::Pcf
                    : a.filter == "roulette" ? scene::VisibilityFilter::Roulette
                                             : scene::VisibilityFilter::Nearest;
  settings.specular = {float(a.specular[0]), float(a.specular[1]), float(a.specular[2])};
  if (!(a.shininess >= 0.0 && a.shininess <= scene::kMaxShininess))
    throw InputError("--shininess must be within [0, " + std::to_string(int(scene::kMaxShininess)) + "]");
  settings.shininess = float(a.shininess);
  settings.time_budget = a.time_budget;
  // --time-budget alone: as many passes as fit; --passes alone or with it: at most that many.
  const bool passes_given = a.passes_option && a.passes_option->count() > 0;
  settings.passes = passes_given || !(a.time_budget > 0.0) ? a.passes : scene::kMaxPasses;
  for (const auto& l : a.area_lights) {
    scene::AreaLight light{vec(l, 0), vec(l, 3), vec(l, 6)};
    light.radiance = l.size() == 12 ? Vec3{l[9], l[10], l[11]} : Vec3{l[9], l[9], l[9]};
    scene::validate_area_light(light, center, layout.radius);
    settings.lights.push_back(light);
  }
  scene::validate(settings);

  scene::PerspectiveCamera camera = scene::framing_camera(center, layout.radius, a.width, a.height, a.camera_fov);
  if (!a.camera_pos.empty()) camera.position = vec(a.camera_pos, 0);
  if (!a.camera_look.empty()) camera.target = vec(a.camera_look, 0);
  const scene::Vec3 forward = camera.target - camera.position;
  if (!(scene::length(forward) > 0.0) || scene::length(scene::cross(scene::normalize(forward), camera.up_hint)) < 1e-6)
    throw InputError("--camera-pos and --camera-look must differ, and the view must not be vertical");

  // The object: its mesh (or built-in) as the file names it, or --mesh. It must lie in the
  // stack's bounding sphere, or it is not the object the stack was built from.
  const std::string source = a.mesh.empty() ? file.source : a.mesh;
  const scene::SceneGeometry object = scene::load_coherent_object(source);
  double reach = 0.0;
  for (const scene::TriMesh& m : object.meshes)
    for (const scene::Vec3& v : m.vertices) reach = std::max(reach, scene::length(v - center));
  for (const scene::Sphere& sp : object.spheres) reach = std::max(reach, scene::length(sp.center - center) + sp.radius);
  if (reach > layout.radius * 1.001 + 1e-9)
    throw InputError("object '" + source + "' reaches outside the stack's bounding sphere: not the object " + a.file +
                     " was built from (--mesh names it)");
  const scene::RayTracer tracer(object);
  const std::array<float, 3> albedo{float(a.albedo[0]), float(a.albedo[1]), float(a.albedo[2])};
  const scene::GBuffer g = scene::render_gbuffer(tracer, camera, layout.radius, albedo, a.threads);

  scene::RenderStats stats;
  HostImage image;
  std::string device_name;
  if (a.reference == "embree") {
    image = scene::render_traced(tracer, g, env, settings, &stats);
    device_name = "Embree occlusion rays";
  } else {
    const std::shared_ptr<Runtime> rt = Runtime::create(a.device);
    image = scene::render_coherent(*rt, file.stack, g, env, settings, &stats);
    device_name = "coherent maps (" + a.filter + ") on " + rt->info().device_name;
  }
  std::vector<io::ImageToWrite> outputs{{a.output, &image}};
  const HostImage mapped = tone_mapped(image);
  const bool png_output = a.output.size() >= 4 && a.output.compare(a.output.size() - 4, 4, ".png") == 0;
  if (png_output) outputs[0].image = &mapped;
  if (!preview.empty()) outputs.push_back({preview, &mapped});
  io::write_images(outputs);
  if (!a.quiet) {
    const double queries = scene::render_queries(g, env, settings, stats.passes);
    std::cout << "coherent render: " << a.output << ": " << a.width << "x" << a.height << ", " << g.hits
              << " pixels on the object, " << stats.passes << (stats.passes == 1 ? " pass" : " passes") << " of "
              << a.samples << " samples (env " << (env.sampled ? "1" : "0") << " + lights " << settings.lights.size()
              << " a sample), " << device_name << ": " << fixed(stats.seconds, 3) << " s, "
              << fixed(queries / std::max(stats.seconds, 1e-9) / 1e6, 1) << " M samples/s\n";
  }
  return 0;
}

int run_sky(const SkyArgs& a) {
  io::write_image(a.output, scene::synthetic_sky(a.options));
  return 0;
}

}  // namespace

void add_coherent_render_commands(CLI::App& coherent, CoherentCommands& out) {
  auto r = std::make_shared<RenderArgs>();
  CLI::App* c = coherent.add_subcommand(
      "render", "Direct lighting of a .csm file's object by an environment map and area lights (Monte Carlo)");
  c->add_option("file", r->file, ".csm file (coherent build)")->required();
  c->add_option("--envmap", r->envmap, "Lat-long environment map (EXR, HDR, ...; row 0 at +y)")->required();
  c->add_option("-o,--out", r->output, "Output image: .exr (linear RGB), .png (tone-mapped), .tif, .pfm")->required();
  c->add_option("--samples", r->samples, "Samples per pixel (env, and per area light)")->capture_default_str();
  c->add_option("--width", r->width, "Image width")->capture_default_str();
  c->add_option("--height", r->height, "Image height")->capture_default_str();
  c->add_option("--camera-pos", r->camera_pos, "Camera position x y z (default: framing the bounding sphere)")
      ->expected(3);
  c->add_option("--camera-look", r->camera_look, "Point the camera looks at (default: the sphere's centre)")
      ->expected(3);
  c->add_option("--camera-fov", r->camera_fov, "Vertical field of view, degrees")->capture_default_str();
  c->add_option("--area-light", r->area_lights,
                "Two-sided rectangle: corner, edge a, edge b (x y z each) and radiance (grey or r g b); repeatable; "
                "must lie outside the bounding sphere")
      ->expected(10, 12)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  c->add_option("--albedo", r->albedo, "Diffuse albedo r g b in [0, 1]")->expected(3)->capture_default_str();
  c->add_option("--specular", r->specular,
                "Glossy (modified Phong) reflectance r g b in [0, 1]; albedo + specular <= 1 per channel")
      ->expected(3)
      ->capture_default_str();
  c->add_option("--shininess", r->shininess, "Phong exponent of the glossy lobe, in [0, 10000]")->capture_default_str();
  c->add_option("--filter", r->filter,
                "Visibility lookup: nearest (view and texel, 0 or 1), pcf (2x2 views x 2x2 texels, fractional) or "
                "roulette (one of pcf's 16 tests drawn by its weight: pcf in expectation at nearest's cost)")
      ->capture_default_str();
  r->passes_option =
      c->add_option("--passes", r->passes,
                    "Progressive passes of --samples each, averaged (default 1, or as many as --time-budget allows)");
  c->add_option("--time-budget", r->time_budget,
                "Seconds: stop before a pass that would end past it (at least one pass; 0 = none)")
      ->capture_default_str();
  c->add_option("--reference", r->reference,
                "embree: the same samples with Embree occlusion rays instead of the coherent maps (host threads)");
  c->add_option("--mesh", r->mesh, "The object's mesh, when the file's source path does not reach it");
  c->add_option("--seed", r->seed, "Seed of the per-pixel random numbers")->capture_default_str();
  c->add_option("--threads", r->threads, "Host threads of the G-buffer and --reference (0 = all cores)")
      ->capture_default_str();
  c->add_option("--device", r->device, "OpenCL device (index, P:D, gpu, cpu or a name)");
  c->add_flag("--preview", r->preview, "Also write OUTPUT.png, tone-mapped");
  c->add_flag("-q,--quiet", r->quiet, "No summary line");
  out.subcommands.push_back({c, [r] { return run_render(*r); }});

  auto s = std::make_shared<SkyArgs>();
  CLI::App* k = coherent.add_subcommand("sky", "Write the synthetic sky (lat-long, half-float EXR)");
  k->add_option("-o,--out", s->output, "Output image (.exr)")->required();
  k->add_option("--width", s->options.width, "Width")->capture_default_str();
  k->add_option("--height", s->options.height, "Height")->capture_default_str();
  k->add_option("--sun-elevation", s->options.sun_elevation, "Sun elevation, degrees")->capture_default_str();
  k->add_option("--sun-azimuth", s->options.sun_azimuth, "Sun azimuth from +x toward +z, degrees")
      ->capture_default_str();
  k->add_option("--sun-radius", s->options.sun_radius, "Sun disc's angular radius, degrees")->capture_default_str();
  k->add_option("--sun-radiance", s->options.sun_radiance, "Sun disc's radiance")->capture_default_str();
  out.subcommands.push_back({k, [s] { return run_sky(*s); }});
}

}  // namespace sf::cli

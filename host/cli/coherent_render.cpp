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
#include "coherent_scene.hpp"
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
  std::vector<std::string> files, meshes;
  std::string envmap, output, filter = "nearest", reference, device;
  int samples = 16, width = 512, height = 512, threads = 0;
  unsigned seed = 1;
  std::vector<double> camera_pos, camera_look, albedo{0.8, 0.8, 0.8}, specular{0.0, 0.0, 0.0};
  double camera_fov = 40.0, shininess = 32.0, time_budget = 0.0;
  int passes = 1;
  CLI::Option* passes_option = nullptr;  // not given: 1 pass, or as many as --time-budget allows
  std::vector<std::vector<double>> area_lights, place, rotate, move, spin;
  std::vector<double> ground_plane, ground_albedo{0.8, 0.8, 0.8};
  std::string local_light;
  std::vector<double> local_radiance{1.0};
  int frames = 1;
  double camera_orbit = 0.0;
  bool preview = false, quiet = false;
};

inline constexpr int kMaxFrames = 10000;

// Frame f's output: OUTPUT itself for one frame, else OUTPUT with _%04d before its extension.
std::string frame_path(const std::string& output, int frame, int frames) {
  if (frames == 1) return output;
  const size_t slash = output.find_last_of('/'), dot = output.find_last_of('.');
  const size_t at = dot == std::string::npos || (slash != std::string::npos && dot < slash) ? output.size() : dot;
  char tag[16];
  std::snprintf(tag, sizeof tag, "_%04d", frame);
  return output.substr(0, at) + tag + output.substr(at);
}

// Object index K of a per-object option (1-based on the command line), checked.
size_t object_index(double k, size_t objects, const char* option) {
  if (!(k >= 1.0 && k <= double(objects) && k == std::floor(k)))
    throw InputError(std::string(option) + ": the object number must be 1 .. " + std::to_string(objects));
  return size_t(k) - 1;
}

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
  if (a.frames < 1 || a.frames > kMaxFrames)
    throw InputError("--frames must be in [1, " + std::to_string(kMaxFrames) + "]");
  if (!std::isfinite(a.camera_orbit)) throw InputError("--camera-orbit must be finite");
  if (!a.meshes.empty() && a.meshes.size() != a.files.size())
    throw InputError("--mesh: one per .csm file (" + std::to_string(a.files.size()) + "), got " +
                     std::to_string(a.meshes.size()));
  if (a.files.size() > size_t(scene::kMaxObjects))
    throw InputError("at most " + std::to_string(scene::kMaxObjects) + " objects");
  for (double c : a.ground_albedo)
    if (!(c >= 0.0 && c <= 1.0)) throw InputError("--ground-albedo must be within [0, 1]");
  if (!a.ground_plane.empty() && !std::isfinite(a.ground_plane[0])) throw InputError("--ground-plane must be finite");
  std::vector<std::string> outputs_checked, inputs{a.envmap};
  for (int f = 0; f < a.frames; ++f) outputs_checked.push_back(frame_path(a.output, f, a.frames));
  const std::string preview = a.preview ? io::preview_path(a.output) : std::string();
  if (a.preview)
    for (int f = 0; f < a.frames; ++f) outputs_checked.push_back(io::preview_path(frame_path(a.output, f, a.frames)));
  inputs.insert(inputs.end(), a.files.begin(), a.files.end());
  inputs.push_back(a.local_light);
  inputs.insert(inputs.end(), a.meshes.begin(), a.meshes.end());
  io::check_outputs(outputs_checked, inputs);

  // The objects: each file's maps, its mesh (or built-in) as the file names it or --mesh, which
  // must lie in the maps' bounding sphere (else it is not the object the maps were built from),
  // and its placement and motion.
  std::vector<io::CoherentFile> files;
  for (const std::string& f : a.files) {
    files.push_back(io::read_coherent(f));
    if (files.back().local)
      throw InputError("'" + f +
                       "' holds a local light's depth cube maps, not an object's views (--local-light "
                       "takes it)");
  }
  const std::array<float, 3> albedo{float(a.albedo[0]), float(a.albedo[1]), float(a.albedo[2])};
  std::vector<scene::SceneObject> objects(files.size());
  for (size_t k = 0; k < files.size(); ++k) {
    scene::SceneObject& o = objects[k];
    o.stack = &files[k].stack;
    o.albedo = albedo;
    const std::string source = a.meshes.empty() ? files[k].source : a.meshes[k];
    o.geometry = scene::load_coherent_object(source);
    const scene::Vec3 c = o.center();
    double reach = 0.0;
    for (const scene::TriMesh& m : o.geometry.meshes)
      for (const scene::Vec3& v : m.vertices) reach = std::max(reach, scene::length(v - c));
    for (const scene::Sphere& sp : o.geometry.spheres)
      reach = std::max(reach, scene::length(sp.center - c) + sp.radius);
    if (reach > o.radius() * 1.001 + 1e-9)
      throw InputError("object '" + source + "' reaches outside the stack's bounding sphere: not the object " +
                       a.files[k] + " was built from (--mesh names it)");
  }
  for (const auto& r : a.rotate) {
    scene::SceneObject& o = objects[object_index(r[0], objects.size(), "--rotate")];
    o.placement = o.placement.then(scene::rotation_about(vec(r, 1), r[4], o.placement.apply(o.center()), "--rotate"));
  }
  for (const auto& p : a.place) {
    scene::SceneObject& o = objects[object_index(p[0], objects.size(), "--place")];
    if (!std::isfinite(p[1]) || !std::isfinite(p[2]) || !std::isfinite(p[3]))
      throw InputError("--place: the translation must be finite");
    o.placement = o.placement.then(scene::translation_by(vec(p, 1)));
  }
  for (const auto& m : a.move) {
    scene::SceneObject& o = objects[object_index(m[0], objects.size(), "--move")];
    if (!std::isfinite(m[1]) || !std::isfinite(m[2]) || !std::isfinite(m[3]))
      throw InputError("--move: the translation must be finite");
    o.move = vec(m, 1);
  }
  for (const auto& r : a.spin) {
    scene::SceneObject& o = objects[object_index(r[0], objects.size(), "--spin")];
    scene::rotation_about(vec(r, 1), r[4], o.center(), "--spin");  // checks the axis and angle
    o.spin_axis = vec(r, 1);
    o.spin_degrees = r[4];
  }

  const scene::EnvMap env = scene::load_envmap(a.envmap);
  scene::RenderSettings settings;
  settings.samples = a.samples;
  settings.seed = a.seed;
  settings.threads = a.threads;
  settings.filter = a.filter == "pcf"        ? scene::VisibilityFilter::Pcf
                    : a.filter == "roulette" ? scene::VisibilityFilter::Roulette
                                             : scene::VisibilityFilter::Nearest;
  settings.specular = {float(a.specular[0]), float(a.specular[1]), float(a.specular[2])};
  settings.shininess = float(a.shininess);  // scene::validate checks its range, as every setting's
  settings.time_budget = a.time_budget;
  // --time-budget alone: as many passes as fit; --passes alone or with it: at most that many.
  const bool passes_given = a.passes_option && a.passes_option->count() > 0;
  settings.passes = passes_given || !(a.time_budget > 0.0) ? a.passes : scene::kMaxPasses;
  for (const auto& l : a.area_lights) {
    scene::AreaLight light{vec(l, 0), vec(l, 3), vec(l, 6)};
    light.radiance = l.size() == 12 ? Vec3{l[9], l[10], l[11]} : Vec3{l[9], l[9], l[9]};
    // Semi-local lights lie outside every object, in every frame.
    for (int f = 0; f < a.frames; ++f)
      for (const scene::SceneObject& o : objects)
        scene::validate_area_light(light, o.at_frame(f).apply(o.center()), o.radius());
    settings.lights.push_back(light);
  }
  // A fixed local light: its depth cube maps around the one object they were built for, unmoved.
  io::CoherentFile local_file;
  if (!a.local_light.empty()) {
    local_file = io::read_coherent(a.local_light);
    if (!local_file.local)
      throw InputError("--local-light: '" + a.local_light + "' holds distant views, not a local light's cube maps");
    const coherent::StackLayout& ll = local_file.stack.layout;
    const coherent::StackLayout& ol = files[0].stack.layout;
    if (files.size() != 1 || !a.place.empty() || !a.rotate.empty() || !a.move.empty() || !a.spin.empty())
      throw InputError(
          "--local-light lights the one object its cube maps were built around, where it was built (no "
          "other objects, --place, --rotate, --move or --spin)");
    if (local_file.source != files[0].source || ll.center[0] != ol.center[0] || ll.center[1] != ol.center[1] ||
        ll.center[2] != ol.center[2] || ll.radius != ol.radius)
      throw InputError("--local-light: '" + a.local_light + "' was built around '" + local_file.source + "', not " +
                       a.files[0] + "'s object");
    const coherent::LocalLight& g = *local_file.local;
    if (!g.is_mesh() && !(scene::length(scene::cross(g.edge_a, g.edge_b)) > 0.0))
      throw InputError("--local-light: the render takes rectangles and meshes (this light is a segment)");
    if (a.local_radiance.size() != 1 && a.local_radiance.size() != 3)
      throw InputError("--local-radiance takes a grey or an r g b radiance");
    const Vec3 radiance = a.local_radiance.size() == 3
                              ? Vec3{a.local_radiance[0], a.local_radiance[1], a.local_radiance[2]}
                              : Vec3{a.local_radiance[0], a.local_radiance[0], a.local_radiance[0]};
    for (int c = 0; c < 3; ++c)
      if (!(radiance[c] >= 0.0 && radiance[c] <= scene::kMaxRadiance))
        throw InputError("--local-radiance must be finite, >= 0 and <= 1e20");
    settings.local_light = scene::RenderSettings::LocalLightSource{g, radiance};
  }
  scene::validate(settings);

  // The camera frames the objects at frame 0; --camera-orbit turns it about the vertical axis
  // through the point it looks at, per frame.
  scene::Vec3 center;
  double radius = 0.0;
  scene::scene_bounds(objects, 0, &center, &radius);
  scene::PerspectiveCamera camera = scene::framing_camera(center, radius, a.width, a.height, a.camera_fov);
  if (!a.camera_pos.empty()) camera.position = vec(a.camera_pos, 0);
  if (!a.camera_look.empty()) camera.target = vec(a.camera_look, 0);
  const scene::Vec3 forward = camera.target - camera.position;
  if (!(scene::length(forward) > 0.0) || scene::length(scene::cross(scene::normalize(forward), camera.up_hint)) < 1e-6)
    throw InputError("--camera-pos and --camera-look must differ, and the view must not be vertical");
  std::vector<scene::GroundPlane> planes;
  if (!a.ground_plane.empty()) {
    scene::GroundPlane p;
    p.height = a.ground_plane[0];
    p.half_size = 4.0 * radius;
    p.cx = center.x;
    p.cz = center.z;
    p.albedo = {float(a.ground_albedo[0]), float(a.ground_albedo[1]), float(a.ground_albedo[2])};
    planes.push_back(p);
  }

  std::shared_ptr<Runtime> rt;
  if (a.reference != "embree") rt = Runtime::create(a.device);
  std::vector<HostImage> images, mapped;
  images.reserve(a.frames);
  mapped.reserve(a.frames);
  const bool png_output = a.output.size() >= 4 && a.output.compare(a.output.size() - 4, 4, ".png") == 0;
  for (int f = 0; f < a.frames; ++f) {
    scene::PerspectiveCamera cam = camera;
    if (f > 0 && a.camera_orbit != 0.0)
      cam.position =
          scene::rotation_about({0.0, 1.0, 0.0}, a.camera_orbit * f, cam.target, "--camera-orbit").apply(cam.position);
    std::vector<std::array<float, 3>> albedo_of_geometry;
    const scene::SceneGeometry world = scene::world_geometry(objects, planes, f, &albedo_of_geometry);
    const scene::RayTracer tracer(world);
    const scene::GBuffer g = scene::render_gbuffer(tracer, cam, radius, albedo_of_geometry, a.threads);
    scene::RenderStats stats;
    std::string device_name;
    if (a.reference == "embree") {
      images.push_back(scene::render_traced(tracer, g, env, settings, &stats));
      device_name = "Embree occlusion rays";
    } else {
      images.push_back(scene::render_coherent(*rt, scene::placed_stacks(objects, f), g, env, settings, &stats,
                                              settings.local_light ? &local_file.stack : nullptr));
      device_name = "coherent maps (" + a.filter + ") on " + rt->info().device_name;
    }
    mapped.push_back(png_output || a.preview ? tone_mapped(images.back()) : HostImage());
    if (!a.quiet) {
      const double queries = scene::render_queries(g, env, settings, stats.passes);
      std::cout << "coherent render: " << frame_path(a.output, f, a.frames) << ": " << a.width << "x" << a.height
                << ", " << objects.size() << (objects.size() == 1 ? " object, " : " objects, ") << g.hits
                << " pixels on surfaces, " << stats.passes << (stats.passes == 1 ? " pass" : " passes") << " of "
                << a.samples << " samples (env " << (env.sampled ? "1" : "0") << " + lights " << settings.lights.size()
                << (settings.local_light ? " + local 1" : "") << " a sample), " << device_name << ": "
                << fixed(stats.seconds, 3) << " s, " << fixed(queries / std::max(stats.seconds, 1e-9) / 1e6, 1)
                << " M samples/s\n";
    }
  }
  // Every frame written together at the end: a failed run leaves none of them.
  std::vector<io::ImageToWrite> outputs;
  std::vector<std::string> paths;
  paths.reserve(2 * size_t(a.frames));
  for (int f = 0; f < a.frames; ++f) {
    paths.push_back(frame_path(a.output, f, a.frames));
    outputs.push_back({paths.back(), png_output ? &mapped[f] : &images[f]});
    if (a.preview) {
      paths.push_back(io::preview_path(frame_path(a.output, f, a.frames)));
      outputs.push_back({paths.back(), &mapped[f]});
    }
  }
  io::write_images(outputs);
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
  c->add_option("files", r->files, ".csm files (coherent build): one object each")->required();
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
  c->add_option("--mesh", r->meshes,
                "The objects' meshes, one per file in order, when the files' source paths do not reach them");
  c->add_option("--place", r->place, "Object K (1-based) translated by x y z: K X Y Z; repeatable")
      ->expected(4)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  c->add_option("--rotate", r->rotate,
                "Object K rotated about its maps' centre (before --place): K AX AY AZ DEGREES; repeatable")
      ->expected(5)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  c->add_option("--move", r->move, "Object K's translation per frame: K DX DY DZ; repeatable")
      ->expected(4)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  c->add_option("--spin", r->spin, "Object K's rotation per frame about its centre: K AX AY AZ DEGREES; repeatable")
      ->expected(5)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  c->add_option("--local-light", r->local_light,
                "A fixed local light's depth cube maps (coherent build --local-light) around the object: lights it "
                "with that rectangle");
  c->add_option("--local-radiance", r->local_radiance, "The local light's radiance (grey or r g b)")
      ->expected(1, 3)
      ->capture_default_str();
  c->add_option("--frames", r->frames, "Frames to render (OUTPUT_0000.ext, ...; one frame: OUTPUT)")
      ->capture_default_str();
  c->add_option("--camera-orbit", r->camera_orbit,
                "Degrees per frame the camera turns about the vertical axis through the point it looks at")
      ->capture_default_str();
  c->add_option("--ground-plane", r->ground_plane,
                "A receiver-only ground plane y = Y under the objects: takes their shadows, casts none")
      ->expected(1);
  c->add_option("--ground-albedo", r->ground_albedo, "The ground plane's albedo r g b")
      ->expected(3)
      ->capture_default_str();
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

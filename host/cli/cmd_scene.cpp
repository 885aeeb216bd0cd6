// `shadowfilter scene`: generates a test scene (built-in or a mesh file) with its shadow map,
// receivers and ray-traced hard and soft references.
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "finite_numbers.hpp"
#include "scene_files.hpp"
#include "scene_generate.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

std::optional<scene::Vec3> parse_vector(const std::vector<double>& values, const char* option) {
  if (values.empty()) return std::nullopt;
  if (values.size() != 3) throw InputError(std::string(option) + " expects three numbers X Y Z (or X,Y,Z)");
  return scene::Vec3{values[0], values[1], values[2]};
}

}  // namespace

CLI::App* add_scene_command(CLI::App& app, SceneArgs& a) {
  CLI::App* c =
      app.add_subcommand("scene", "Generate a scene: shadow map, receivers, ray-traced hard and soft references");
  c->add_option("scene", a.scene,
                "Built-in scene (spheres, fence, backyard, contact, thin, terrain, city, treeline) or a mesh "
                "file (OBJ, PLY, OFF, STL)")
      ->required();
  c->add_option("-o,--out", a.out_dir, "Output directory (appears complete or not at all)")->required();
  c->add_option("--size", a.map_size, "Shadow-map width and height in texels")->capture_default_str();
  c->add_option("--receivers", a.receivers, "Camera-view size WIDTHxHEIGHT")->capture_default_str();
  c->add_option("--light", a.light, "Light projection: ortho|perspective")->capture_default_str();
  c->add_option("--light-dir", a.light_dir, "Light direction X Y Z (into the scene)")->expected(3)->delimiter(',');
  c->add_option("--light-pos", a.light_pos, "Perspective light position X Y Z")->expected(3)->delimiter(',');
  c->add_option("--fov", a.fov, "Perspective light field of view in degrees (default: fitted)");
  add_light_size_option(c, a.light_size,
                        "Area light: L (a square) or W,H (W along the light's right, H along its down), "
                        "light-space units (default: the scene's square)");
  c->add_option("--samples", a.samples, "Area-light samples per pixel (a square number)")->capture_default_str();
  c->add_option("--soft-reference", a.soft_reference,
                "Soft reference's samples from the surface point at the pixel's centre (centre) or over the "
                "whole pixel (pixel: the antialiased pixel, what footprint lookups estimate); default: the "
                "scene's (pixel for grazing, centre for the others)")
      ->check(CLI::IsMember({"centre", "pixel"}));
  c->add_option("--seed", a.seed, "Seed of the area-light sampling")->capture_default_str();
  c->add_option("--threads", a.threads, "Worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_flag("-q,--quiet", a.quiet, "No progress bars or summary");
  c->add_option("--camera-pos", a.camera_pos, "Camera position X,Y,Z (default: the scene's)")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--camera-look", a.camera_look, "Point the camera looks at X,Y,Z (default: the scene's)")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--camera-fov", a.camera_fov, "Camera's vertical field of view in degrees (default: the scene's)");
  c->add_option("--camera-near", a.camera_near,
                "Nearest view depth a layout covers (default: the scene's, or from its bounding box)");
  c->add_option("--camera-far", a.camera_far,
                "Farthest view depth a layout covers (default: the scene's, or from its bounding box)");
  c->add_option("--frames", a.frames, "Frames along the camera path (1..1000; > 1: DIR/frame_000, ...)")
      ->capture_default_str();
  c->add_option("--camera-path", a.camera_path,
                "walk (a straight line, same look direction) | orbit (about the "
                "look point, constant height)")
      ->capture_default_str();
  c->add_option("--camera-to", a.camera_to, "Walk's end X,Y,Z (default: 10% of far ahead on the ground)")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--orbit-degrees", a.orbit_degrees, "Orbit's whole angle (default 30)");
  c->add_option("--layout", a.layout, "Cascade layout to render: single|pssm|tsm|pssm+tsm (cascade_K.exr per frame)");
  c->add_option("--cascades", a.cascades, "Layers of pssm and pssm+tsm (default 4)")->each([&a](const std::string&) {
    a.cascades_given = true;
  });
  c->add_option("--split-lambda", a.split_lambda, "Practical split blend: 0 uniform .. 1 logarithmic (default 0.75)");
  c->add_flag("--no-stabilize", a.no_stabilize, "Tight layer boxes instead of texel-snapped bounding spheres");
  c->add_option("--tsm-focus", a.tsm_focus, "TSM focus: fraction of the slice's log depth range (default 0.8)");
  c->add_option("--cascade-blend", a.cascade_blend, "Blend band at the end of each layer's split (default 0.1)");
  return c;
}

int run_scene(const SceneArgs& a) {
  scene::SceneRequest request;
  request.scene = a.scene;
  request.out_dir = a.out_dir;
  request.map_size = a.map_size;
  request.receivers = a.receivers;
  request.light = a.light;
  request.light_dir = parse_vector(a.light_dir, "--light-dir");
  request.light_pos = parse_vector(a.light_pos, "--light-pos");
  if (!std::isnan(a.fov)) {
    // 0 is the request's "fitted"; a given field of view is an angle.
    if (!(a.fov > 0.0)) throw InputError("--fov must lie in (0, 170) degrees, got " + scene::format_number(a.fov));
    request.fov_degrees = a.fov;
  }
  if (!a.light_size.empty()) request.light_size = a.light_size[0];
  if (a.light_size.size() == 2) request.light_height = a.light_size[1];
  request.samples = a.samples;
  if (!a.soft_reference.empty()) request.pixel_average = a.soft_reference == "pixel";
  request.seed = a.seed;
  request.progress = !a.quiet;
  request.threads = a.threads;
  const auto given = [](double x) { return std::isnan(x) ? std::nullopt : std::optional<double>(x); };
  request.camera.position = parse_vector(a.camera_pos, "--camera-pos");
  request.camera.look = parse_vector(a.camera_look, "--camera-look");
  request.camera.fov_degrees = given(a.camera_fov);
  request.camera.near_depth = given(a.camera_near);
  request.camera.far_depth = given(a.camera_far);
  request.camera.frames = a.frames;
  request.camera.path = a.camera_path;
  request.camera.walk_to = parse_vector(a.camera_to, "--camera-to");
  request.camera.orbit_degrees = given(a.orbit_degrees);
  request.layout.layout = a.layout;
  if (a.cascades_given) request.layout.cascades = a.cascades;
  request.layout.split_lambda = given(a.split_lambda);
  request.layout.tsm_focus = given(a.tsm_focus);
  request.layout.blend = given(a.cascade_blend);
  request.layout.no_stabilize = a.no_stabilize;
  const scene::SceneSummary s = scene::generate_scene(request);
  if (!a.quiet) {
    std::cout << "scene '" << s.setup.geometry.name << "' written to " << a.out_dir << ": " << s.setup.map_width << "x"
              << s.setup.map_height << " map, " << s.setup.camera.width << "x" << s.setup.camera.height << " view, "
              << s.setup.geometry.triangle_count() << " triangles, " << s.setup.geometry.spheres.size()
              << " spheres, light " << (s.setup.light.type == scene::LightType::Ortho ? "ortho" : "perspective")
              << " near/far " << scene::format_number(s.setup.light.near_plane) << "/"
              << scene::format_number(s.setup.light.far_plane) << ", size " << scene::format_number(s.setup.light_size)
              << (s.setup.light_height >= 0.0 ? "x" + scene::format_number(s.setup.light_height) : std::string())
              << ", " << s.setup.samples << " samples, " << s.plan.frames.size() << " frame(s)";
    if (s.plan.layout)
      std::cout << ", layout " << layout_name(s.plan.layout->kind) << " ("
                << s.plan.frames.front().layers->layers.size() << " layers)";
    std::cout << ", " << std::fixed;
    std::cout.precision(2);
    std::cout << s.seconds << " s\n";
  }
  return 0;
}

}  // namespace sf::cli

// sf_make_scene: writes the bundled "spheres" scene (shadow map, planar receivers, camera-view
// receivers, ray-traced hard-shadow reference, scene.json) deterministically into a directory.
#include <CLI/CLI.hpp>

#include <cmath>
#include <exception>
#include <iostream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "image_io.hpp"
#include "scene_files.hpp"
#include "scene_render.hpp"
#include "shadowfilter/errors.hpp"

namespace {

using namespace sf::scene;

constexpr int kMaxImageSide = 16384;
// Directional light, pointing down and tilted from vertical.
constexpr Vec3 kLightDirection{0.35, -1.0, 0.25};
// The light frustum is widened by this fraction of its extent on every side.
constexpr double kFrustumMargin = 0.01;

struct Options {
  std::string out_dir;
  int map_size = 512;
  std::string receiver_size = "640x480";
  unsigned seed = 1;
};

struct ImageSize {
  int width = 0;
  int height = 0;
};

void require_valid_side(long long side, const std::string& what) {
  if (side <= 0 || side > kMaxImageSide) {
    throw sf::InputError(what + " must be between 1 and " + std::to_string(kMaxImageSide) +
                         ", got " + std::to_string(side));
  }
}

bool all_digits(const std::string& text) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// "WxH", e.g. "640x480".
ImageSize parse_size(const std::string& text, const std::string& option) {
  const size_t separator = text.find('x');
  const std::string width = text.substr(0, separator);
  const std::string height = separator == std::string::npos ? "" : text.substr(separator + 1);
  if (!all_digits(width) || !all_digits(height)) {
    throw sf::InputError(option + " expects WIDTHxHEIGHT (e.g. 640x480), got '" + text + "'");
  }
  const ImageSize size{std::stoi(width), std::stoi(height)};
  require_valid_side(size.width, option + " width");
  require_valid_side(size.height, option + " height");
  return size;
}

// Oblique view from above one corner, so footprints grow with distance; the floor does not
// fill the frame (background pixels are NaN receivers).
PerspectiveCamera make_camera(ImageSize size) {
  PerspectiveCamera camera;
  camera.position = {7.0, 5.5, 9.0};
  camera.target = {0.0, 0.4, -0.5};
  camera.vertical_fov_degrees = 42.0;
  camera.width = size.width;
  camera.height = size.height;
  return camera;
}

SceneSetup make_setup(const Options& options) {
  require_valid_side(options.map_size, "--size");
  SceneSetup setup;
  setup.geometry = make_spheres_scene();
  setup.light = OrthoLight::fit(setup.geometry, kLightDirection, kFrustumMargin);
  setup.camera = make_camera(parse_size(options.receiver_size, "--receivers"));
  setup.map_width = options.map_size;
  setup.map_height = options.map_size;
  return setup;
}

std::vector<OutputFile> output_files() {
  return {
      {"shadowmap.exr", "shadow map: 1 channel Z, float32 linear light depth, 1 = nothing hit"},
      {"receiver_depth.exr",
       "planar receivers (shadow-map size): 1 channel Z, floor depth without occluders, NaN = "
       "floor not hit"},
      {"receivers.exr",
       "camera-view receivers: u v d (float32) f (half, footprint in level-0 texels from the "
       "pixel's edge rays on the hit tangent plane); NaN = background"},
      {"reference_hard.exr",
       "camera view: ray-traced hard-shadow visibility Y (1 lit, 0 occluded, 1 background)"},
      {"scene.json", "every parameter of the scene"},
  };
}

// OpenImageIO stamps EXR files with the current time (capDate) unless DateTime is given: an
// empty one keeps the files byte-identical between runs.
void write_deterministic(const std::string& path, sf::HostImage image,
                         std::map<std::string, std::string> attributes) {
  attributes["DateTime"] = "";
  image.attributes = std::move(attributes);
  sf::io::write_image(path, image);
}

void write_light_view(const std::string& path, sf::HostImage image, const SceneSetup& setup) {
  write_deterministic(path, std::move(image), light_attributes(setup));
}

void write_camera_view(const std::string& path, sf::HostImage image, const SceneSetup& setup) {
  write_deterministic(path, std::move(image),
                      {{"scene", setup.geometry.name}, {"generator", kGeneratorVersion}});
}

int generate(const Options& options) {
  const SceneSetup setup = make_setup(options);
  const sf::HostImage shadow_map = render_shadow_map(setup);
  const sf::HostImage receiver_depth = render_receiver_depth(setup);

  SceneRecord record;
  record.seed = options.seed;
  record.min_occluder_floor_gap = min_occluder_floor_gap(shadow_map, receiver_depth);
  record.files = output_files();

  StagingDirectory staging(options.out_dir);
  write_light_view(staging.file("shadowmap.exr"), shadow_map, setup);
  write_light_view(staging.file("receiver_depth.exr"), receiver_depth, setup);
  write_camera_view(staging.file("receivers.exr"), render_receivers(setup), setup);
  write_camera_view(staging.file("reference_hard.exr"), render_reference_hard(setup), setup);
  write_scene_json(staging.file("scene.json"), setup, record);
  staging.commit(record.files);

  std::cout << "scene '" << setup.geometry.name << "' written to " << options.out_dir << "\n"
            << "  light near/far: " << format_number(setup.light.near_plane) << " / "
            << format_number(setup.light.far_plane) << "\n"
            << "  min occluder-floor gap (normalised light depth): "
            << format_number(record.min_occluder_floor_gap) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes the bundled 'spheres' scene: shadowmap.exr, receiver_depth.exr, "
               "receivers.exr, reference_hard.exr and scene.json (deterministic)."};
  Options options;
  app.add_option("--out", options.out_dir, "output directory (replaced files appear at once)")
      ->required();
  app.add_option("--size", options.map_size, "shadow-map width and height in texels")
      ->capture_default_str();
  app.add_option("--receivers", options.receiver_size, "camera-view size WIDTHxHEIGHT")
      ->capture_default_str();
  app.add_option("--seed", options.seed,
                 "seed for sampled outputs (the spheres scene samples nothing; recorded in "
                 "scene.json)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "sf_make_scene: error: " << e.what() << "\n";
    return 2;
  }

  try {
    return generate(options);
  } catch (const sf::InputError& e) {
    std::cerr << "sf_make_scene: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sf_make_scene: error: " << e.what() << "\n";
    return 1;
  }
}

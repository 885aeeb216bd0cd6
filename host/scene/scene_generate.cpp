#include "scene_generate.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <utility>

#include "image_io.hpp"
#include "layer_render.hpp"
#include "scene_files.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace {

constexpr int kMaxImageSide = 16384;
// The light frustum is widened by this fraction of its extent on every side.
constexpr double kFrustumMargin = 0.01;

void require_valid_side(long long side, const std::string& what) {
  if (side <= 0 || side > kMaxImageSide)
    throw InputError(what + " must be between 1 and " + std::to_string(kMaxImageSide) + ", got " +
                     std::to_string(side));
}

bool all_digits(const std::string& text) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text)
    if (c < '0' || c > '9') return false;
  return true;
}

std::pair<int, int> parse_size(const std::string& text, const std::string& option) {
  const size_t separator = text.find('x');
  const std::string width = text.substr(0, separator);
  const std::string height = separator == std::string::npos ? "" : text.substr(separator + 1);
  if (!all_digits(width) || !all_digits(height))
    throw InputError(option + " expects WIDTHxHEIGHT (e.g. 640x480), got '" + text + "'");
  const int w = std::stoi(width), h = std::stoi(height);
  require_valid_side(w, option + " width");
  require_valid_side(h, option + " height");
  return {w, h};
}

std::string builtin_list() {
  std::string list;
  for (const std::string& n : builtin_scene_names()) list += (list.empty() ? "" : ", ") + n;
  return list;
}

SceneDefaults load_defaults(const std::string& scene) {
  if (is_builtin_scene(scene)) return make_builtin_scene(scene);
  const bool looks_like_file = scene.find('/') != std::string::npos || scene.find('.') != std::string::npos;
  if (!looks_like_file)
    throw InputError("unknown scene '" + scene + "' (built-in: " + builtin_list() +
                     "; or a mesh file: OBJ, PLY, OFF, STL)");
  return load_mesh_scene(scene);
}

std::vector<OutputFile> light_files(bool has_ground) {
  std::vector<OutputFile> files = {
      {"shadowmap.exr",
       "shadow map: 1 channel Z, float32 linear light depth (methods.md sec. 1), 1 = nothing hit; "
       "near/far and the light in the header"},
  };
  if (has_ground)
    files.push_back({"receiver_depth.exr",
                     "planar receivers (shadow-map size): 1 channel Z, depth of the ground (floor "
                     "or terrain) alone, NaN = ground not hit"});
  return files;
}

// The files of one frame, named inside `dir` ("" = the scene directory itself).
std::vector<OutputFile> frame_files(const std::string& dir, size_t layers) {
  const std::string prefix = dir.empty() ? "" : dir + "/";
  std::vector<OutputFile> files;
  files.push_back({prefix + "receivers.exr",
                   "camera-view receivers: u v d (float32) f (half, footprint in level-0 texels "
                   "from the shadow-map coordinates of the pixel's neighbourhood on the hit "
                   "tangent plane) ndl (half, cosine between the camera-facing normal and the "
                   "direction to the light, <= 0 facing away) nx ny nz (float32, the camera-facing "
                   "normal in light space scaled to one texel: the change of u W, v H, d along it, "
                   "normal_offset.hpp); NaN = background"});
  files.push_back({prefix + "reference_hard.exr",
                   "camera view: ray-traced point-light visibility Y (half; 1 lit, 0 occluded or "
                   "facing away, 1 background)"});
  files.push_back({prefix + "reference_soft.exr",
                   "camera view: ray-traced fraction of the square area light visible Y (half; "
                   "stratified samples, 1 background)"});
  files.push_back({prefix + "view.exr",
                   "camera view for layered maps: P.x P.y P.z (world position of the hit) depth (view "
                   "depth along the camera's axis) dPdx.x..z dPdy.x..z (world offsets across the pixel on "
                   "the hit's tangent plane), float32; ndl (half); NaN = background"});
  for (size_t k = 0; k < layers; ++k)
    files.push_back({prefix + "cascade_" + std::to_string(k) + ".exr",
                     "layer " + std::to_string(k) +
                         " of the cascade set: 1 channel Z, its linear depth d (1 = nothing hit); "
                         "shadowfilter:world_to_map, :split, :layer, :blend and the light in the header"});
  return files;
}

// A cascade file left from an earlier run with more layers (or with layers at all) would be read
// as part of this frame's set.
void remove_stale_layers(const std::filesystem::path& dir, size_t layers) {
  std::error_code ignored;
  for (int k = int(layers); k < sf::kMaxCascadeLayers + 8; ++k)
    std::filesystem::remove(dir / ("cascade_" + std::to_string(k) + ".exr"), ignored);
}

// The scene's files carry its parameters; write_image keeps them byte-identical between runs.
void write_deterministic(const std::string& path, HostImage image, std::map<std::string, std::string> attributes) {
  image.attributes = std::move(attributes);
  io::write_image(path, image);
}

}  // namespace

SceneSetup make_setup(const SceneRequest& request, SceneDefaults* defaults_out) {
  require_valid_side(request.map_size, "--size");
  const auto [cw, ch] = parse_size(request.receivers, "--receivers");
  if (request.light != "ortho" && request.light != "perspective")
    throw InputError("--light must be ortho or perspective, got '" + request.light + "'");
  const bool ortho = request.light == "ortho";
  if (ortho && request.light_pos)
    throw InputError(
        "--light-pos needs --light perspective (an orthographic light has a "
        "direction, --light-dir)");
  if (ortho && request.fov_degrees != 0.0) throw InputError("--fov needs --light perspective");
  if (!ortho && request.fov_degrees != 0.0 && !(request.fov_degrees > 0.0 && request.fov_degrees < 170.0))
    throw InputError("--fov must be between 0 and 170 degrees");
  if (request.light_size && !(*request.light_size >= 0.0 && std::isfinite(*request.light_size)))
    throw InputError("--light-size must be a finite number >= 0");
  if (request.light_height && !(*request.light_height >= 0.0 && std::isfinite(*request.light_height)))
    throw InputError("--light-size W,H: H must be a finite number >= 0");
  if (request.samples <= 0)
    throw InputError("--samples must be a positive square number, got " + std::to_string(request.samples));
  if (request.out_dir.empty()) throw InputError("-o DIR is required");

  SceneDefaults defaults = load_defaults(request.scene);
  SceneSetup setup;
  setup.geometry = defaults.geometry;
  const Vec3 direction = request.light_dir ? *request.light_dir : defaults.light_direction;
  if (!(length(direction) > 0.0)) throw InputError("--light-dir must not be the zero vector");
  if (ortho) {
    setup.light = LightView::fit_ortho(setup.geometry, direction, kFrustumMargin);
  } else {
    // Default position: along -direction from the centre of the scene's bounding box, 2.5
    // bounding radii away.
    const Vec3 dir = normalize(direction);
    const Interval x = project_onto(setup.geometry, {1, 0, 0});
    const Interval y = project_onto(setup.geometry, {0, 1, 0});
    const Interval z = project_onto(setup.geometry, {0, 0, 1});
    const Vec3 centre{0.5 * (x.lo + x.hi), 0.5 * (y.lo + y.hi), 0.5 * (z.lo + z.hi)};
    const double radius = 0.5 * length({x.hi - x.lo, y.hi - y.lo, z.hi - z.lo});
    const Vec3 position = request.light_pos ? *request.light_pos : centre - (2.5 * radius) * dir;
    setup.light = LightView::fit_perspective(setup.geometry, position, centre, request.fov_degrees, kFrustumMargin);
  }
  setup.camera = requested_camera(request.camera, defaults.camera);
  setup.camera.width = cw;
  setup.camera.height = ch;
  setup.map_width = request.map_size;
  setup.map_height = request.map_size;
  setup.light_size = request.light_size ? *request.light_size : defaults.light_size;
  setup.light_height = request.light_height ? *request.light_height : -1.0;
  setup.samples = request.samples;
  setup.pixel_average = request.pixel_average.value_or(defaults.pixel_average);
  setup.seed = request.seed;
  setup.progress = request.progress;
  setup.threads = request.threads;
  if (defaults_out) *defaults_out = std::move(defaults);
  return setup;
}

SceneSummary generate_scene(const SceneRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  SceneDefaults defaults;
  SceneSummary summary;
  summary.setup = make_setup(request, &defaults);
  const SceneSetup& setup = summary.setup;
  summary.plan = plan_frames(request.camera, request.layout, setup, defaults);
  const SceneRenderer renderer(setup);  // validates --samples
  const bool ground = setup.geometry.has_ground();

  // Everything that can fail on input is checked before anything is created.
  StagingDirectory staging(request.out_dir);
  const HostImage shadow_map = renderer.shadow_map();
  write_deterministic(staging.file("shadowmap.exr").string(), shadow_map, light_attributes(setup));
  SceneRecord record;
  record.source = defaults.source;
  record.purpose = defaults.purpose;
  record.plan = summary.plan;
  if (ground) {
    const HostImage receiver_depth = renderer.receiver_depth();
    record.min_occluder_floor_gap = min_occluder_floor_gap(shadow_map, receiver_depth);
    write_deterministic(staging.file("receiver_depth.exr").string(), receiver_depth, light_attributes(setup));
  } else {
    record.min_occluder_floor_gap = std::nan("");
  }
  std::vector<OutputFile> written = light_files(ground);
  record.files = written;
  const std::map<std::string, std::string> camera_attributes = {{"scene", setup.geometry.name},
                                                                {"generator", kGeneratorVersion}};
  auto soft_attributes = camera_attributes;
  add_light_sides(soft_attributes, setup);
  soft_attributes["samples"] = std::to_string(setup.samples);
  soft_attributes["seed"] = std::to_string(setup.seed);
  if (setup.pixel_average) soft_attributes["pixel_average"] = "1";  // the samples cover the pixel, not its centre
  for (const SceneFrame& frame : summary.plan.frames) {
    const std::string prefix = frame.dir.empty() ? "" : frame.dir + "/";
    CameraImages camera = renderer.camera_view(frame.camera, true);
    auto view_attributes = camera_attributes;
    view_attributes["camera_near"] = format_number(frame.depths.near_depth);
    view_attributes["camera_far"] = format_number(frame.depths.far_depth);
    write_deterministic(staging.file(prefix + "receivers.exr").string(), std::move(camera.receivers),
                        camera_attributes);
    write_deterministic(staging.file(prefix + "reference_hard.exr").string(), std::move(camera.reference_hard),
                        camera_attributes);
    write_deterministic(staging.file(prefix + "reference_soft.exr").string(), std::move(camera.reference_soft),
                        soft_attributes);
    write_deterministic(staging.file(prefix + "view.exr").string(), std::move(camera.view), view_attributes);
    const size_t layers = frame.layers ? frame.layers->layers.size() : 0;
    if (frame.layers) {
      std::vector<HostImage> maps = render_layers(renderer.tracer(), *frame.layers, setup.threads, setup.progress);
      for (size_t k = 0; k < maps.size(); ++k)
        write_deterministic(staging.file(prefix + "cascade_" + std::to_string(k) + ".exr").string(), std::move(maps[k]),
                            layer_attributes(setup, *frame.layers, int(k)));
    }
    const std::vector<OutputFile> files = frame_files(frame.dir, layers);
    written.insert(written.end(), files.begin(), files.end());
    if (&frame == &summary.plan.frames.front()) {
      // scene.json lists one frame's files; with several frames their names stand for every
      // frame_NNN directory.
      const std::vector<OutputFile> named = frame_files(frame.dir.empty() ? "" : "frame_NNN", layers);
      record.files.insert(record.files.end(), named.begin(), named.end());
    }
  }
  record.files.push_back({"scene.json", "every parameter of the scene"});
  written.push_back(record.files.back());
  write_scene_json(staging.file("scene.json"), setup, record);
  staging.commit(written);
  const std::filesystem::path out_dir(request.out_dir);
  for (const SceneFrame& frame : summary.plan.frames)
    remove_stale_layers(out_dir / frame.dir, frame.layers ? frame.layers->layers.size() : 0);
  if (!ground) {  // a stale planar-receiver file from an earlier scene would not match
    std::error_code ignored;
    std::filesystem::remove(out_dir / "receiver_depth.exr", ignored);
  }
  summary.min_occluder_floor_gap = record.min_occluder_floor_gap;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace sf::scene

#include "scene_files.hpp"

#include <unistd.h>

#include <charconv>
#include <sstream>
#include <system_error>

#include <cmath>

#include "cascade_io.hpp"
#include "output_file.hpp"
#include "scene_render.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace fs = std::filesystem;
namespace {

std::string interval_text(Interval range) {
  return "[" + format_number(range.lo) + ", " + format_number(range.hi) + "]";
}

void write_geometry(std::ostream& out, const SceneGeometry& geometry) {
  out << "  \"geometry\": {\n"
      << "    \"has_ground\": " << (geometry.has_ground() ? "true" : "false") << ",\n"
      << "    \"triangles\": " << geometry.triangle_count() << ",\n"
      << "    \"vertices\": " << geometry.vertex_count() << ",\n"
      << "    \"spheres\": " << geometry.spheres.size() << ",\n"
      << "    \"objects\": [\n";
  for (size_t k = 0; k < geometry.description.size(); ++k)
    out << "      " << geometry.description[k] << (k + 1 < geometry.description.size() ? ",\n" : "\n");
  out << "    ]\n  },\n";
}

void write_light(std::ostream& out, const SceneSetup& setup) {
  const LightView& light = setup.light;
  const bool ortho = light.type == LightType::Ortho;
  out << "  \"light\": {\n"
      << "    \"type\": " << (ortho ? "\"orthographic\"" : "\"perspective\"") << ",\n"
      << "    \"direction\": " << json_vector(light.forward) << ",\n"
      << "    \"right\": " << json_vector(light.right) << ",\n"
      << "    \"down\": " << json_vector(light.down) << ",\n";
  if (ortho) {
    out << "    \"right_range\": " << interval_text(light.right_range) << ",\n"
        << "    \"down_range\": " << interval_text(light.down_range) << ",\n";
  } else {
    out << "    \"position\": " << json_vector(light.position) << ",\n"
        << "    \"fov_degrees\": " << format_number(light.fov_degrees) << ",\n";
  }
  out << "    \"near\": " << format_number(light.near_plane) << ",\n"
      << "    \"far\": " << format_number(light.far_plane) << ",\n"
      << "    \"mapping\": "
      << json_string(ortho ? "u = (p.right - right_range[0]) / (right_range[1] - right_range[0]), "
                             "v likewise along down, d = (p.direction - near) / (far - near)"
                           : "q = p - position, z = q.direction; u = 1/2 + (q.right / z) / (2 "
                             "tan(fov/2)), v likewise along down, d = (z - near) / (far - near)")
      << ",\n"
      << "    \"size\": " << format_number(setup.light_size) << ",\n"
      << "    \"height\": " << format_number(setup.area_light_height()) << ",\n"
      << "    \"area_light\": "
      << json_string(ortho ? "rectangle of sides size (along right) and height (along down) in the near plane, "
                             "centred on the receiver's projection onto the near plane"
                           : "rectangle of sides size (along right) and height (along down) centred on position")
      << ",\n"
      << "    \"shadow_map_size\": [" << setup.map_width << ", " << setup.map_height << "]\n"
      << "  },\n";
}

void write_camera(std::ostream& out, const PerspectiveCamera& camera) {
  out << "  \"camera\": {\n"
      << "    \"type\": \"perspective\",\n"
      << "    \"position\": " << json_vector(camera.position) << ",\n"
      << "    \"target\": " << json_vector(camera.target) << ",\n"
      << "    \"up\": " << json_vector(camera.up_hint) << ",\n"
      << "    \"vertical_fov_degrees\": " << format_number(camera.vertical_fov_degrees) << ",\n"
      << "    \"size\": [" << camera.width << ", " << camera.height << "]\n"
      << "  },\n";
}

void write_frame_camera(std::ostream& out, const SceneFrame& frame) {
  const PerspectiveCamera& c = frame.camera;
  out << "{\"position\": " << json_vector(c.position) << ", \"target\": " << json_vector(c.target)
      << ", \"up\": " << json_vector(c.up_hint)
      << ", \"vertical_fov_degrees\": " << format_number(c.vertical_fov_degrees) << ", \"size\": [" << c.width << ", "
      << c.height << "], \"near\": " << format_number(frame.depths.near_depth)
      << ", \"far\": " << format_number(frame.depths.far_depth) << "}";
}

// The camera path, the layout and, per frame, its directory, camera and layers (matrix, split).
void write_frames(std::ostream& out, const FramePlan& plan) {
  const CameraPathOptions& p = plan.path;
  const bool walk = p.kind == CameraPathKind::Walk;
  out << "  \"camera_path\": {\"frames\": " << p.frames << ", \"path\": " << (walk ? "\"walk\"" : "\"orbit\"");
  if (walk && plan.frames.size() > 1) {
    const SceneFrame& last = plan.frames.back();
    out << ", \"to\": " << json_vector(last.camera.position);
  }
  if (!walk) out << ", \"orbit_degrees\": " << format_number(p.orbit_degrees);
  out << ", \"view_depth\": \"distance along the camera's axis (position -> target)\"},\n";
  if (plan.layout) {
    const sf::LayoutOptions& o = *plan.layout;
    out << "  \"layout\": {\"kind\": " << json_string(sf::layout_name(o.kind)) << ", \"cascades\": "
        << (plan.frames.empty() || !plan.frames[0].layers ? 0 : plan.frames[0].layers->layers.size())
        << ", \"split_lambda\": " << format_number(o.split_lambda)
        << ", \"stabilize\": " << (o.stabilize ? "true" : "false") << ", \"tsm_focus\": " << format_number(o.tsm_focus)
        << ", \"blend\": "
        << format_number(plan.frames.empty() || !plan.frames[0].layers ? o.blend : plan.frames[0].layers->blend)
        << ", \"size\": [" << o.map_size << ", " << o.map_size << "]"
        << ", \"mapping\": "
        << json_string("world_to_map M (row-major 4x4), p = (x, y, z, 1): u = M0.p / M3.p, v = M1.p / M3.p, d = M2.p")
        << "},\n";
  } else {
    out << "  \"layout\": null,\n";
  }
  out << "  \"frames\": [\n";
  for (size_t i = 0; i < plan.frames.size(); ++i) {
    const SceneFrame& f = plan.frames[i];
    out << "    {\"dir\": " << json_string(f.dir.empty() ? "." : f.dir) << ", \"camera\": ";
    write_frame_camera(out, f);
    out << ", \"layers\": [";
    if (f.layers) {
      for (size_t k = 0; k < f.layers->layers.size(); ++k) {
        const sf::CascadeLayer& layer = f.layers->layers[k];
        out << (k ? ",\n" : "\n") << "      {\"file\": \"cascade_" << k << ".exr\", \"world_to_map\": [";
        for (int e = 0; e < 16; ++e) out << (e ? ", " : "") << format_number(layer.transform.m[e]);
        out << "], \"split\": [" << format_number(layer.split_near) << ", " << format_number(layer.split_far) << "]}";
      }
      out << "\n    ";
    }
    out << "]}" << (i + 1 < plan.frames.size() ? ",\n" : "\n");
  }
  out << "  ],\n";
}

void write_files(std::ostream& out, const std::vector<OutputFile>& files) {
  out << "  \"files\": [\n";
  for (size_t k = 0; k < files.size(); ++k) {
    out << "    {\"name\": " << json_string(files[k].name) << ", \"description\": " << json_string(files[k].description)
        << "}" << (k + 1 < files.size() ? ",\n" : "\n");
  }
  out << "  ]\n";
}

fs::path without_trailing_separator(const fs::path& path) {
  fs::path normal = fs::absolute(path).lexically_normal();
  return normal.has_filename() ? normal : normal.parent_path();
}

}  // namespace

std::string format_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string json_vector(Vec3 v) {
  return "[" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + "]";
}

void add_light_sides(std::map<std::string, std::string>& a, const SceneSetup& setup) {
  a["light_size"] = format_number(setup.light_size);
  if (setup.light_height >= 0.0) a["light_height"] = format_number(setup.light_height);
}

std::map<std::string, std::string> light_attributes(const SceneSetup& setup) {
  const LightView& light = setup.light;
  std::map<std::string, std::string> a = {
      {"scene", setup.geometry.name},
      {"generator", kGeneratorVersion},
      {"light_type", light.type == LightType::Ortho ? "orthographic" : "perspective"},
      {"near", format_number(light.near_plane)},
      {"far", format_number(light.far_plane)},
      {"light_direction", json_vector(light.forward)},
      {"light_right", json_vector(light.right)},
      {"light_down", json_vector(light.down)},
      {"depth", "linear: (view depth - near) / (far - near)"},
  };
  add_light_sides(a, setup);
  if (light.type == LightType::Ortho) {
    // Light-space extents: [right_min, right_max, down_min, down_max] in world units.
    a["ortho_extents"] = "[" + format_number(light.right_range.lo) + ", " + format_number(light.right_range.hi) + ", " +
                         format_number(light.down_range.lo) + ", " + format_number(light.down_range.hi) + "]";
  } else {
    a["light_position"] = json_vector(light.position);
    a["fov_degrees"] = format_number(light.fov_degrees);
  }
  return a;
}

std::map<std::string, std::string> layer_attributes(const SceneSetup& setup, const sf::CascadeSet& set, int k) {
  std::map<std::string, std::string> a = io::cascade_layer_attributes(set, k);
  const LightView& light = setup.light;
  a["scene"] = setup.geometry.name;
  a["generator"] = kGeneratorVersion;
  a["light_type"] = "orthographic";
  a["light_direction"] = json_vector(light.forward);
  a["light_right"] = json_vector(light.right);
  a["light_down"] = json_vector(light.down);
  add_light_sides(a, setup);
  // The area light's plane as a world depth along the light's axis (the single map's near plane,
  // where the scene's ray-traced soft reference puts the light): soft --cascades reads it.
  a["light_plane"] = format_number(light.near_plane);
  a["depth"] = "linear: d = M2 . (x, y, z, 1) of shadowfilter:world_to_map";
  // Row r of the matrix is (axis / length, -lo / length) for the range [lo, lo + length] along
  // the axis (cascade_layout.cpp); d's row gives near/far for every layout, u's and v's the
  // extents where the layer is not warped (M3 = (0, 0, 0, 1)).
  const auto& m = set.layers.at(k).transform.m;
  const auto range = [&](int r, double& lo, double& hi) {
    const double scale = std::sqrt(m[4 * r] * m[4 * r] + m[4 * r + 1] * m[4 * r + 1] + m[4 * r + 2] * m[4 * r + 2]);
    lo = -m[4 * r + 3] / scale;
    hi = lo + 1.0 / scale;
  };
  double near_plane = 0, far_plane = 0;
  range(2, near_plane, far_plane);
  a["near"] = format_number(near_plane);
  a["far"] = format_number(far_plane);
  if (m[12] == 0.0 && m[13] == 0.0 && m[14] == 0.0 && m[15] == 1.0) {
    double r0 = 0, r1 = 0, d0 = 0, d1 = 0;
    range(0, r0, r1);
    range(1, d0, d1);
    a["ortho_extents"] =
        "[" + format_number(r0) + ", " + format_number(r1) + ", " + format_number(d0) + ", " + format_number(d1) + "]";
  }
  return a;
}

void write_scene_json(const fs::path& path, const SceneSetup& setup, const SceneRecord& record) {
  std::ostringstream out;
  out << "{\n"
      << "  \"scene\": " << json_string(setup.geometry.name) << ",\n"
      << "  \"source\": " << json_string(record.source) << ",\n"
      << "  \"purpose\": " << json_string(record.purpose) << ",\n"
      << "  \"generator\": " << json_string(kGeneratorVersion) << ",\n"
      << "  \"seed\": " << setup.seed << ",\n"
      << "  \"samples\": " << setup.samples << ",\n"
      << "  \"sampling\": "
      << json_string(
             "stratified: sqrt(samples) x sqrt(samples) cells over the area light, one jittered sample per cell, "
             "per-pixel streams from splitmix64(seed, x, y)")
      << ",\n"
      << "  \"conventions\": " << json_string("methods.md section 1; world y up, units arbitrary") << ",\n";
  write_geometry(out, setup.geometry);
  write_light(out, setup);
  write_camera(out, setup.camera);
  write_frames(out, record.plan);
  out << "  \"min_occluder_floor_gap\": " << format_number(record.min_occluder_floor_gap) << ",\n";
  write_files(out, record.files);
  out << "}\n";

  io::write_text(path.string(), "scene description", out.str());
}

StagingDirectory::StagingDirectory(const fs::path& destination)
    : destination_(without_trailing_separator(destination)) {
  const fs::path parent = destination_.parent_path();
  std::error_code error;
  fs::create_directories(parent, error);
  if (error) throw InputError("cannot create " + parent.string() + ": " + error.message());
  if (fs::exists(destination_) && !fs::is_directory(destination_)) {
    throw InputError(destination_.string() + " exists and is not a directory");
  }
  staging_ =
      parent / ("." + destination_.filename().string() + ".partial-" + std::to_string(static_cast<long>(::getpid())));
  fs::remove_all(staging_, error);
  io::mark_unfinished_directory(staging_.string());
  if (!fs::create_directory(staging_, error) || error) {
    io::unmark_unfinished_directory(staging_.string());
    throw InputError("cannot create " + staging_.string() + ": " + error.message());
  }
}

fs::path StagingDirectory::file(const std::string& name) const {
  const fs::path path = staging_ / name;
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  if (error) throw InputError("cannot create " + path.parent_path().string() + ": " + error.message());
  return path;
}

StagingDirectory::~StagingDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
  io::unmark_unfinished_directory(staging_.string());
}

void StagingDirectory::commit(const std::vector<OutputFile>& files) {
  std::error_code error;
  if (!fs::exists(destination_)) {
    fs::rename(staging_, destination_, error);
    if (error) throw InputError("cannot create " + destination_.string() + ": " + error.message());
    io::unmark_unfinished_directory(staging_.string());
    committed_ = true;
    return;
  }
  for (const OutputFile& output : files) {
    fs::create_directories((destination_ / output.name).parent_path(), error);
    if (error)
      throw InputError("cannot create " + (destination_ / output.name).parent_path().string() + ": " + error.message());
    fs::rename(staging_ / output.name, destination_ / output.name, error);
    if (error) {
      throw InputError("cannot write " + (destination_ / output.name).string() + ": " + error.message());
    }
  }
  fs::remove_all(staging_, error);  // with the emptied frame directories
  io::unmark_unfinished_directory(staging_.string());
  committed_ = true;
}

}  // namespace sf::scene

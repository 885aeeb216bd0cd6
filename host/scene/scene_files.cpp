#include "scene_files.hpp"

#include <unistd.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <system_error>

#include <cmath>

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
      << "    \"area_light\": "
      << json_string(ortho ? "square of side size in the near plane, sides along right/down, "
                             "centred on the receiver's projection onto the near plane"
                           : "square of side size centred on position, sides along right/down")
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
      {"light_size", format_number(setup.light_size)},
      {"depth", "linear: (view depth - near) / (far - near)"},
  };
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
  out << "  \"min_occluder_floor_gap\": " << format_number(record.min_occluder_floor_gap) << ",\n";
  write_files(out, record.files);
  out << "}\n";

  std::ofstream file(path, std::ios::binary);
  file << out.str();
  file.close();
  if (!file) throw InputError("cannot write " + path.string());
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
  if (!fs::create_directory(staging_, error) || error) {
    throw InputError("cannot create " + staging_.string() + ": " + error.message());
  }
}

StagingDirectory::~StagingDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagingDirectory::commit(const std::vector<OutputFile>& files) {
  std::error_code error;
  if (!fs::exists(destination_)) {
    fs::rename(staging_, destination_, error);
    if (error) throw InputError("cannot create " + destination_.string() + ": " + error.message());
    committed_ = true;
    return;
  }
  for (const OutputFile& output : files) {
    fs::rename(staging_ / output.name, destination_ / output.name, error);
    if (error) {
      throw InputError("cannot write " + (destination_ / output.name).string() + ": " + error.message());
    }
  }
  fs::remove(staging_, error);
  committed_ = true;
}

}  // namespace sf::scene

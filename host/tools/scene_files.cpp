#include "scene_files.hpp"

#include <unistd.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <system_error>

#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace fs = std::filesystem;
namespace {

std::string vector_text(Vec3 v) {
  return "[" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + "]";
}

std::string interval_text(Interval range) {
  return "[" + format_number(range.lo) + ", " + format_number(range.hi) + "]";
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void write_geometry(std::ostream& out, const SceneGeometry& geometry) {
  out << "  \"geometry\": {\n"
      << "    \"floor\": {\"plane\": \"y = 0\", \"half_size\": "
      << format_number(geometry.floor.half_size) << "},\n"
      << "    \"sphere\": {\"center\": " << vector_text(geometry.sphere.center)
      << ", \"radius\": " << format_number(geometry.sphere.radius) << "},\n"
      << "    \"box\": {\"min\": " << vector_text(geometry.box.min_corner)
      << ", \"max\": " << vector_text(geometry.box.max_corner) << "}\n"
      << "  },\n";
}

void write_light(std::ostream& out, const OrthoLight& light, int map_width, int map_height) {
  out << "  \"light\": {\n"
      << "    \"type\": \"orthographic\",\n"
      << "    \"direction\": " << vector_text(light.forward) << ",\n"
      << "    \"right\": " << vector_text(light.right) << ",\n"
      << "    \"down\": " << vector_text(light.down) << ",\n"
      << "    \"right_range\": " << interval_text(light.right_range) << ",\n"
      << "    \"down_range\": " << interval_text(light.down_range) << ",\n"
      << "    \"near\": " << format_number(light.near_plane) << ",\n"
      << "    \"far\": " << format_number(light.far_plane) << ",\n"
      << "    \"mapping\": " << quoted("u = (p.right - right_range[0]) / (right_range[1] - "
                                       "right_range[0]), v likewise along down, d = (p.direction "
                                       "- near) / (far - near)")
      << ",\n"
      << "    \"shadow_map_size\": [" << map_width << ", " << map_height << "]\n"
      << "  },\n";
}

void write_camera(std::ostream& out, const PerspectiveCamera& camera) {
  out << "  \"camera\": {\n"
      << "    \"type\": \"perspective\",\n"
      << "    \"position\": " << vector_text(camera.position) << ",\n"
      << "    \"target\": " << vector_text(camera.target) << ",\n"
      << "    \"up\": " << vector_text(camera.up_hint) << ",\n"
      << "    \"vertical_fov_degrees\": " << format_number(camera.vertical_fov_degrees) << ",\n"
      << "    \"size\": [" << camera.width << ", " << camera.height << "]\n"
      << "  },\n";
}

void write_files(std::ostream& out, const std::vector<OutputFile>& files) {
  out << "  \"files\": [\n";
  for (size_t k = 0; k < files.size(); ++k) {
    out << "    {\"name\": " << quoted(files[k].name)
        << ", \"description\": " << quoted(files[k].description) << "}"
        << (k + 1 < files.size() ? ",\n" : "\n");
  }
  out << "  ]\n";
}

fs::path without_trailing_separator(const fs::path& path) {
  fs::path normal = fs::absolute(path).lexically_normal();
  return normal.has_filename() ? normal : normal.parent_path();
}

}  // namespace

std::string format_number(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::map<std::string, std::string> light_attributes(const SceneSetup& setup) {
  const OrthoLight& light = setup.light;
  return {
      {"scene", setup.geometry.name},
      {"generator", kGeneratorVersion},
      {"near", format_number(light.near_plane)},
      {"far", format_number(light.far_plane)},
      {"light_direction", vector_text(light.forward)},
      {"light_right", vector_text(light.right)},
      {"light_down", vector_text(light.down)},
      // Light-space extents: [right_min, right_max, down_min, down_max] in world units.
      {"ortho_extents", "[" + format_number(light.right_range.lo) + ", " +
                            format_number(light.right_range.hi) + ", " +
                            format_number(light.down_range.lo) + ", " +
                            format_number(light.down_range.hi) + "]"},
      {"depth", "linear: (distance from near plane) / (far - near)"},
  };
}

void write_scene_json(const fs::path& path, const SceneSetup& setup, const SceneRecord& record) {
  std::ostringstream out;
  out << "{\n"
      << "  \"scene\": " << quoted(setup.geometry.name) << ",\n"
      << "  \"generator\": " << quoted(kGeneratorVersion) << ",\n"
      << "  \"seed\": " << record.seed << ",\n"
      << "  \"conventions\": " << quoted("methods.md section 1; world y up, units arbitrary")
      << ",\n";
  write_geometry(out, setup.geometry);
  write_light(out, setup.light, setup.map_width, setup.map_height);
  write_camera(out, setup.camera);
  out << "  \"min_occluder_floor_gap\": " << format_number(record.min_occluder_floor_gap)
      << ",\n";
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
  staging_ = parent / ("." + destination_.filename().string() + ".partial-" +
                       std::to_string(static_cast<long>(::getpid())));
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
      throw InputError("cannot write " + (destination_ / output.name).string() + ": " +
                       error.message());
    }
  }
  fs::remove(staging_, error);
  committed_ = true;
}

}  // namespace sf::scene

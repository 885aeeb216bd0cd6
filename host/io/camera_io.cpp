// Camera and light files (camera_io.hpp).
#include "camera_io.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "depth_decode.hpp"
#include "input_file.hpp"
#include "io_detail.hpp"
#include "shadowfilter/errors.hpp"
#include "output_file.hpp"

namespace sf::io {
namespace {

using nlohmann::json;

constexpr size_t kMaxViewFileBytes = size_t(1) << 20;
constexpr int kMaxNesting = 8;

[[noreturn]] void refuse(const std::string& source, const std::string& problem) {
  throw InputError(source + ": " + detail::one_line(problem));
}

// Nesting of arrays and objects outside strings: the parser's recursion and the value's
// destruction stay shallow whatever the text.
void require_shallow(const std::string& text, const std::string& source) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char ch : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (ch == '\\')
        escaped = true;
      else if (ch == '"')
        in_string = false;
      continue;
    }
    if (ch == '"') in_string = true;
    if (ch == '[' || ch == '{') {
      if (++depth > kMaxNesting) refuse(source, "nested deeper than " + std::to_string(kMaxNesting) + " levels");
    } else if (ch == ']' || ch == '}') {
      --depth;
    }
  }
}

std::string json_error(const std::string& what) {
  // "[json.exception.parse_error.101] parse error at line 1, ..." without the bracketed id, and
  // with the bytes it quotes from the file made printable (the file may be anything).
  const size_t end = what.find("] ");
  std::string text = what.compare(0, 1, "[") == 0 && end != std::string::npos ? what.substr(end + 2) : what;
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return text;
}

std::array<double, 16> matrix(const json& value, const std::string& key, const std::string& source) {
  std::vector<const json*> numbers;
  if (value.is_array() && value.size() == 16) {
    for (const json& v : value) numbers.push_back(&v);
  } else if (value.is_array() && value.size() == 4) {
    for (const json& row : value) {
      if (!row.is_array() || row.size() != 4) break;
      for (const json& v : row) numbers.push_back(&v);
    }
  }
  if (numbers.size() != 16)
    refuse(source, "\"" + key + "\" must be 16 numbers, row-major (or 4 rows of 4), got " +
                       std::string(value.type_name()) +
                       (value.is_array() ? " of " + std::to_string(value.size()) : ""));
  std::array<double, 16> m{};
  for (size_t i = 0; i < 16; ++i) {
    if (!numbers[i]->is_number()) refuse(source, "\"" + key + "\" element " + std::to_string(i) + " is not a number");
    m[i] = numbers[i]->get<double>();
    if (!std::isfinite(m[i])) refuse(source, "\"" + key + "\" element " + std::to_string(i) + " is not finite");
  }
  return m;
}

int image_size(const json& value, const std::string& key, const std::string& source) {
  if (!value.is_number_integer() || value.get<long long>() <= 0 || value.get<long long>() > (1 << 20))
    refuse(source, "\"" + key + "\" must be a positive integer (pixels)");
  return int(value.get<long long>());
}

}  // namespace

ViewFile parse_view_file(const std::string& text, const std::string& source) {
  require_shallow(text, source);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    refuse(source, "not JSON (" + json_error(e.what()) + ")");
  }
  if (!doc.is_object())
    refuse(source, std::string("expected an object {\"view\": [...], \"projection\": [...]}, got ") + doc.type_name());
  ViewFile file;
  ViewProjection& vp = file.view_projection;
  bool has_view = false, has_projection = false;
  for (const auto& [key, value] : doc.items()) {
    if (key == "view") {
      vp.view = matrix(value, key, source);
      has_view = true;
    } else if (key == "projection") {
      vp.projection = matrix(value, key, source);
      has_projection = true;
    } else if (key == "clip") {
      const std::string clip = value.is_string() ? value.get<std::string>() : "";
      if (clip == "opengl")
        vp.clip = ClipSpace::OpenGL;
      else if (clip == "d3d")
        vp.clip = ClipSpace::D3D;
      else if (clip == "vulkan")
        vp.clip = ClipSpace::Vulkan;
      else
        refuse(source, "\"clip\" must be \"opengl\", \"d3d\" or \"vulkan\", got " + detail::one_line(value.dump()));
    } else if (key == "reversed_z") {
      if (!value.is_boolean()) refuse(source, "\"reversed_z\" must be true or false");
      vp.reversed_z = value.get<bool>();
    } else if (key == "far") {
      if (!value.is_number() || !std::isfinite(value.get<double>()))
        refuse(source, "\"far\" must be a finite number (the depth that becomes d = 1 under an infinite far plane)");
      vp.infinite_far_depth = value.get<double>();
    } else if (key == "width") {
      file.width = image_size(value, key, source);
    } else if (key == "height") {
      file.height = image_size(value, key, source);
    } else {
      refuse(source, "unknown key \"" + detail::one_line(key) +
                         "\"; valid: view, projection, clip, reversed_z, far, width, height");
    }
  }
  if (!has_view || !has_projection)
    refuse(source, std::string("needs \"view\" and \"projection\" (16 numbers each, row-major); ") +
                       (has_view ? "\"projection\"" : "\"view\"") + " is missing");
  try {
    (void)projection_depth(vp);
  } catch (const InputError& e) {
    std::string message = e.what();
    const std::string field = "ViewProjection::infinite_far_depth";
    if (const size_t at = message.find(field); at != std::string::npos) message.replace(at, field.size(), "\"far\"");
    refuse(source, message);
  }
  return file;
}

ViewFile load_view_file(const std::string& path, const std::string& role) {
  const std::string source = role + " '" + detail::one_line(path) + "'";
  const uint64_t size = require_regular_file(path, role);
  record_input(path);
  if (size > kMaxViewFileBytes)
    refuse(source, std::to_string(size) + " bytes; a camera or light file is a few hundred (at most 1 MiB read)");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) refuse(source, "read failed");
  return parse_view_file(text.str(), source);
}

CameraDepthKind parse_camera_depth_kind(const std::string& name) {
  for (CameraDepthKind k :
       {CameraDepthKind::Window, CameraDepthKind::View, CameraDepthKind::Distance, CameraDepthKind::Position})
    if (name == camera_depth_kind_name(k)) return k;
  throw InputError("unknown camera depth kind '" + detail::one_line(name) +
                   "'; valid: window, view, distance, position");
}

CameraDepth load_camera_depth(const std::string& path, CameraDepthKind kind) {
  const std::string role = "camera depth";
  const detail::RawImage raw = detail::read_raw(path, role);
  detail::require_16_bit_depth(raw, role, path);
  CameraDepth depth;
  depth.width = raw.width;
  depth.height = raw.height;
  depth.kind = kind;
  if (kind != CameraDepthKind::Position) {
    depth.values = detail::single_depth_channel(raw, path, role);
    return depth;
  }
  const std::vector<int> c =
      detail::three_channels(raw, {{"P.x", "P.y", "P.z"}, {"X", "Y", "Z"}, {"x", "y", "z"}}, path, role);
  depth.values.resize(raw.texels() * 3);
  for (size_t t = 0; t < raw.texels(); ++t)
    for (int k = 0; k < 3; ++k) depth.values[t * 3 + size_t(k)] = raw.at(t, c[size_t(k)]);
  return depth;
}

std::vector<float> load_normal_image(const std::string& path, int width, int height) {
  const std::string role = "normal image";
  const detail::RawImage raw = detail::read_raw(path, role);
  if (!raw.stored_format.is_floating_point())
    detail::fail(role, path,
                 std::string("pixel data is ") + raw.stored_format.c_str() +
                     "; normals need a float image (EXR, TIFF, PFM) holding world-space x y z in [-1, 1]");
  if (raw.width != width || raw.height != height)
    detail::fail(role, path,
                 "size " + std::to_string(raw.width) + "x" + std::to_string(raw.height) +
                     " differs from the camera's " + std::to_string(width) + "x" + std::to_string(height));
  const std::vector<int> c =
      detail::three_channels(raw, {{"N.x", "N.y", "N.z"}, {"X", "Y", "Z"}, {"x", "y", "z"}}, path, role);
  std::vector<float> normals(raw.texels() * 3);
  for (size_t t = 0; t < raw.texels(); ++t)
    for (int k = 0; k < 3; ++k) normals[t * 3 + size_t(k)] = raw.at(t, c[size_t(k)]);
  return normals;
}

void image_size(const std::string& path, const std::string& role, int* width, int* height) {
  const detail::RawImage raw = detail::read_raw(path, role);
  *width = raw.width;
  *height = raw.height;
}

}  // namespace sf::io

// Reading and describing layered shadow maps (cascade_io.hpp).
#include "cascade_io.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

#include "image_io.hpp"
#include "io_detail.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::io {
namespace {

namespace fs = std::filesystem;
using detail::fail;

const char* const kLayerRole = "cascade layer";
const char* const kViewRole = "view file";

std::string exact(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// The numbers of a header attribute; exactly `count` finite ones, else InputError.
std::vector<double> numbers(const detail::RawImage& raw, const std::string& path, const std::string& key,
                            size_t count) {
  const auto it = raw.attributes.find(key);
  if (it == raw.attributes.end()) fail(kLayerRole, path, "its header has no " + key + " attribute");
  std::istringstream in(it->second);
  in.imbue(std::locale::classic());
  std::vector<double> values;
  double x = 0;
  while (in >> x) values.push_back(x);
  if (!in.eof() || values.size() != count)
    fail(kLayerRole, path, key + " must hold " + std::to_string(count) + " numbers, found '" + it->second + "'");
  for (double v : values)
    if (!std::isfinite(v)) fail(kLayerRole, path, key + " holds a non-finite number");
  return values;
}

}  // namespace

std::vector<std::string> cascade_files(const std::string& dir_or_list) {
  std::vector<std::string> files;
  std::error_code ec;
  if (fs::is_directory(dir_or_list, ec)) {
    for (int k = 0;; ++k) {
      const fs::path file = fs::path(dir_or_list) / ("cascade_" + std::to_string(k) + ".exr");
      if (!fs::exists(file, ec)) break;
      files.push_back(file.string());
    }
    if (files.empty()) throw InputError("--cascades '" + dir_or_list + "': the directory holds no cascade_0.exr");
    return files;
  }
  std::string item;
  std::istringstream in(dir_or_list);
  while (std::getline(in, item, ','))
    if (!item.empty()) files.push_back(item);
  if (files.empty()) throw InputError("--cascades names no layer file");
  return files;
}

LayeredMaps load_cascade_set(const std::vector<std::string>& paths) {
  if (paths.empty()) throw InputError("a cascade set needs at least one layer file");
  if (paths.size() > static_cast<size_t>(kMaxCascadeLayers))
    throw InputError("a cascade set holds at most " + std::to_string(kMaxCascadeLayers) + " layers, " +
                     std::to_string(paths.size()) + " files given");
  LayeredMaps out;
  for (size_t k = 0; k < paths.size(); ++k) {
    const std::string& path = paths[k];
    const detail::RawImage raw = detail::read_raw(path, kLayerRole);
    const std::vector<double> m = numbers(raw, path, "shadowfilter:world_to_map", 16);
    const std::vector<double> split = numbers(raw, path, "shadowfilter:split", 2);
    const std::vector<double> index = numbers(raw, path, "shadowfilter:layer", 2);
    const std::vector<double> blend = numbers(raw, path, "shadowfilter:blend", 1);
    if (index[0] != static_cast<double>(k) || index[1] != static_cast<double>(paths.size()))
      fail(kLayerRole, path,
           "its header says layer " + exact(index[0]) + " of " + exact(index[1]) + ", but it is file " +
               std::to_string(k) + " of " + std::to_string(paths.size()));
    if (k == 0) {
      out.set.width = raw.width;
      out.set.height = raw.height;
      out.set.blend = blend[0];
    } else if (raw.width != out.set.width || raw.height != out.set.height) {
      fail(kLayerRole, path,
           "size " + std::to_string(raw.width) + "x" + std::to_string(raw.height) + " differs from layer 0's " +
               std::to_string(out.set.width) + "x" + std::to_string(out.set.height) +
               " (every layer of a set has one size)");
    }
    CascadeLayer layer;
    std::copy(m.begin(), m.end(), layer.transform.m.begin());
    layer.split_near = split[0];
    layer.split_far = split[1];
    out.set.layers.push_back(layer);
    out.maps.push_back(load_depth_map(path, DepthLoadOptions{}));
  }
  validate(out.set);
  return out;
}

std::map<std::string, std::string> cascade_layer_attributes(const CascadeSet& set, int k) {
  const CascadeLayer& layer = set.layers.at(k);
  std::string matrix;
  for (size_t i = 0; i < 16; ++i) matrix += (i ? " " : "") + exact(layer.transform.m[i]);
  return {{"shadowfilter:world_to_map", matrix},
          {"shadowfilter:split", exact(layer.split_near) + " " + exact(layer.split_far)},
          {"shadowfilter:layer", std::to_string(k) + " " + std::to_string(set.layers.size())},
          {"shadowfilter:blend", exact(set.blend)}};
}

const std::vector<std::string>& view_channel_names() {
  static const std::vector<std::string> names{"P.x",    "P.y",    "P.z",    "depth",  "dPdx.x", "dPdx.y",
                                              "dPdx.z", "dPdy.x", "dPdy.y", "dPdy.z", "ndl"};
  return names;
}

ViewReceivers load_view_receivers(const std::string& path) {
  const detail::RawImage raw = detail::read_raw(path, kViewRole);
  if (!raw.stored_format.is_floating_point())
    fail(kViewRole, path, "expected float channels, found " + std::string(raw.stored_format.c_str()));
  const auto& names = view_channel_names();
  std::vector<int> column(names.size(), -1);
  for (int c = 0; c < raw.channels; ++c)
    for (size_t n = 0; n < names.size(); ++n)
      if (raw.channel_names.size() > static_cast<size_t>(c) && raw.channel_names[c] == names[n]) column[n] = c;
  for (size_t n = 0; n + 1 < names.size(); ++n)
    if (column[n] < 0) fail(kViewRole, path, "has no channel " + names[n] + " (a view file names its channels)");
  ViewReceivers v;
  v.width = raw.width;
  v.height = raw.height;
  const size_t count = raw.texels();
  std::vector<float>* arrays[10] = {&v.x, &v.y, &v.z, &v.depth, &v.dxx, &v.dxy, &v.dxz, &v.dyx, &v.dyy, &v.dyz};
  for (auto* a : arrays) a->resize(count);
  const bool has_ndl = column.back() >= 0;
  if (has_ndl) v.ndl.resize(count);
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  for (size_t t = 0; t < count; ++t) {
    bool finite = true;
    for (int n = 0; n < 10; ++n) {
      const float value = raw.at(t, column[n]);
      (*arrays[n])[t] = value;
      finite = finite && std::isfinite(value);
    }
    if (!finite)
      for (auto* a : arrays) (*a)[t] = kNaN;
    if (has_ndl) v.ndl[t] = raw.at(t, column.back());
  }
  return v;
}

}  // namespace sf::io

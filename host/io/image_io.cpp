// Reading shadow maps and receivers (methods.md sec. 1). Writing lives in image_write.cpp.
#include "image_io.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "exr_header.hpp"
#include "image_bounds.hpp"
#include "input_file.hpp"
#include "io_detail.hpp"

namespace sf::io {
namespace {

using detail::check_declared_image_size;
using detail::check_exr_header;
using detail::details_suffix;
using detail::fail;
using detail::is_exr_file;
using detail::RawImage;
using detail::read_raw;

const char* const kShadowMapRole = "shadow map";
const char* const kReceiverImageRole = "receiver image";
const char* const kReceiverDepthRole = "receiver depth";

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

std::string texel_text(const RawImage& img, size_t texel) {
  return "(x=" + std::to_string(texel % img.width) + ", y=" + std::to_string(texel / img.width) + ")";
}

// The file's channel type; with per-channel formats, the first one that isn't floating point
// (so that a single integer channel makes the whole image "not float").
OIIO::TypeDesc stored_channel_format(const OIIO::ImageSpec& spec) {
  for (int c = 0; c < spec.nchannels; ++c)
    if (!spec.channelformat(c).is_floating_point()) return spec.channelformat(c);
  return spec.format;
}

void require_plain_2d(const OIIO::ImageSpec& spec, const std::string& path, const std::string& role) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(role, path,
         "zero size image (" + size_text(spec.width, spec.height) + ", " + std::to_string(spec.nchannels) +
             " channels)");
  if (spec.deep) fail(role, path, "deep images are not supported");
  if (spec.depth > 1) fail(role, path, "volume images (depth > 1) are not supported");
}

bool same_value(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }

// The single depth channel of a 1-channel image, or of a 3/4-channel image whose first three
// channels agree everywhere (RGB-only formats such as Radiance HDR; a 4th channel is ignored).
std::vector<float> single_depth_channel(const RawImage& img, const std::string& path, const std::string& role) {
  if (img.channels == 1) return img.pixels;
  if (img.channels != 3 && img.channels != 4)
    fail(role, path,
         "expected 1 channel (or 3-4 channels with identical first three), found " + std::to_string(img.channels) +
             " channels");
  std::vector<float> depth(img.texels());
  for (size_t t = 0; t < img.texels(); ++t) {
    const float first = img.at(t, 0);
    if (!same_value(first, img.at(t, 1)) || !same_value(first, img.at(t, 2)))
      fail(role, path,
           "expected 1 channel, or 3-4 channels with identical first three; found " + std::to_string(img.channels) +
               " channels that differ at " + texel_text(img, t));
    depth[t] = first;
  }
  return depth;
}

void require_valid_planes(const DepthLoadOptions& opt, const std::string& path, const std::string& role) {
  if (opt.encoding == DepthEncoding::Linear) return;
  if (!(opt.near_plane > 0.0) || !(opt.far_plane > opt.near_plane) || !std::isfinite(opt.far_plane)) {
    std::ostringstream problem;
    problem << "perspective/reversed depth needs 0 < --near < --far (got near=" << opt.near_plane
            << ", far=" << opt.far_plane << ")";
    fail(role, path, problem.str());
  }
}

double clamp01(double value) { return std::min(1.0, std::max(0.0, value)); }

// Linear depth of every texel; non-finite texels stay NaN.
std::vector<float> linearize_all(std::vector<float> stored, const DepthLoadOptions& opt) {
  for (float& value : stored) value = std::isfinite(value) ? static_cast<float>(linearize_depth(value, opt)) : kNaN;
  return stored;
}

// Shadow maps have no background: non-finite texels are an error or the far plane.
void resolve_nonfinite_depth(std::vector<float>& depth, const RawImage& img, const DepthLoadOptions& opt,
                             const std::string& path) {
  size_t count = 0;
  size_t first = 0;
  for (size_t t = 0; t < depth.size(); ++t) {
    if (std::isfinite(depth[t])) continue;
    if (count++ == 0) first = t;
    depth[t] = 1.0f;
  }
  if (count > 0 && opt.nonfinite == NonFinitePolicy::Error)
    fail(kShadowMapRole, path,
         std::to_string(count) + " non-finite depth texel" + (count == 1 ? "" : "s") + " (NaN/Inf), first at " +
             texel_text(img, first) + "; use --nonfinite far to treat them as the far plane");
}

// Returns the index of each wanted channel name, or an empty vector if any is missing.
std::vector<int> find_channels(const RawImage& img, const std::vector<std::string>& wanted) {
  std::vector<int> indices;
  for (const std::string& name : wanted) {
    const auto it = std::find(img.channel_names.begin(), img.channel_names.end(), name);
    if (it == img.channel_names.end()) return {};
    indices.push_back(static_cast<int>(it - img.channel_names.begin()));
  }
  return indices;
}

// Channel indices of u, v, d[, f[, ndl]]: by name when the file's channels are exactly
// u v d [f [ndl]] (in any order), else positional R G B [A [5th]].
std::vector<int> receiver_channel_order(const RawImage& img) {
  std::vector<std::string> names{"u", "v", "d", "f", "ndl"};
  names.resize(size_t(img.channels));
  std::vector<int> by_name = find_channels(img, names);
  if (!by_name.empty()) return by_name;
  std::vector<int> positional(img.channels);
  for (int c = 0; c < img.channels; ++c) positional[c] = c;
  return positional;
}

void require_float_receivers(const RawImage& img, const std::string& path) {
  if (img.stored_format.is_floating_point()) return;
  fail(kReceiverImageRole, path,
       std::string("pixel data is ") + img.stored_format.c_str() +
           ", receivers need a float image (EXR/TIFF/PFM, float32 or half); 8/16-bit formats "
           "such as PNG cannot hold receiver coordinates");
}

}  // namespace

namespace detail {

std::unique_ptr<OIIO::ImageInput> open_checked_image(const std::string& path, const std::string& role) {
  const uint64_t file_bytes = require_regular_file(path, role);
  return with_out_of_memory_named(path, role, [&] {
    if (is_exr_file(path)) check_exr_header(path, file_bytes, role);
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);  // keep stored values: never premultiply
    auto input = OIIO::ImageInput::open(path, &config);
    if (!input) fail(role, path, "not a readable image" + details_suffix(OIIO::geterror()));
    require_plain_2d(input->spec(), path, role);
    check_declared_image_size(input->spec(), input->format_name(), file_bytes, path, role);
    return input;
  });
}

// Reads subimage 0, miplevel 0 as float, once open_checked_image has checked everything that
// needs no pixels. OIIO readers report a truncated or corrupt file either by read_image()
// returning false or only by a pending error message, so both are checked (and the message is
// always consumed so that it can't leak into a later call).
RawImage read_raw(const std::string& path, const std::string& role) {
  auto input = open_checked_image(path, role);
  return with_out_of_memory_named(path, role, [&] {
    const OIIO::ImageSpec& spec = input->spec();
    RawImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.nchannels;
    img.channel_names = spec.channelnames;
    img.stored_format = stored_channel_format(spec);
    for (const OIIO::ParamValue& p : spec.extra_attribs)
      if (p.type() == OIIO::TypeString) img.attributes[p.name().string()] = p.get_string();
    img.pixels.resize(img.texels() * img.channels);

    const bool read_ok = input->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.pixels.data());
    const std::string read_error = input->geterror();
    const bool close_ok = input->close();
    const std::string close_error = input->geterror();
    if (!read_ok || !read_error.empty() || !close_ok || !close_error.empty())
      fail(role, path,
           "cannot read pixels, file truncated or corrupt" +
               details_suffix(read_error.empty() ? close_error : read_error));
    return img;
  });
}

}  // namespace detail

DepthEncoding parse_depth_encoding(const std::string& name) {
  if (name == "linear") return DepthEncoding::Linear;
  if (name == "perspective") return DepthEncoding::Perspective;
  if (name == "reversed") return DepthEncoding::Reversed;
  throw InputError("unknown depth encoding '" + detail::one_line(name) + "'; valid: linear, perspective, reversed");
}

// Assumes valid planes (0 < near < far; the loaders check them). Stored values are clamped to
// [0,1] before decoding: both decodings are monotonic on [0,1], and outside it the formulas
// would run past the far plane's pole and produce depths of the wrong sign.
//
//   perspective (conventional [0,1] depth, near -> 0, far -> 1):
//     z = F (z_view - N) / (z_view (F - N))   =>   z_view = N F / (F - z (F - N))
//   reversed (standard reversed-Z, near -> 1, far -> 0):
//     z_rev = N (F - z_view) / (z_view (F - N))   =>   z_view = N F / (N + z_rev (F - N))
//     (for a finite far plane this equals 1 - z of the conventional mapping)
//   linear depth = (z_view - N) / (F - N), clamped to [0,1].
double linearize_depth(double stored, const DepthLoadOptions& opt) {
  if (!std::isfinite(stored)) return std::numeric_limits<double>::quiet_NaN();
  const double z = clamp01(stored);
  const double n = opt.near_plane;
  const double f = opt.far_plane;
  switch (opt.encoding) {
    case DepthEncoding::Linear:
      return z;
    case DepthEncoding::Perspective:
      return clamp01((n * f / (f - z * (f - n)) - n) / (f - n));
    case DepthEncoding::Reversed:
      return clamp01((n * f / (n + z * (f - n)) - n) / (f - n));
  }
  return z;
}

HostImage load_depth_map(const std::string& path, const DepthLoadOptions& opt) {
  require_valid_planes(opt, path, kShadowMapRole);
  const RawImage raw = read_raw(path, kShadowMapRole);
  HostImage depth_map;
  depth_map.width = raw.width;
  depth_map.height = raw.height;
  depth_map.channels = 1;
  depth_map.data = linearize_all(single_depth_channel(raw, path, kShadowMapRole), opt);
  resolve_nonfinite_depth(depth_map.data, raw, opt, path);
  return depth_map;
}

// Non-finite u, v or f also make a texel background: such a receiver has no defined lookup.
Receivers load_receiver_image(const std::string& path) {
  const RawImage raw = read_raw(path, kReceiverImageRole);
  if (raw.channels < 3 || raw.channels > 5)
    fail(kReceiverImageRole, path,
         "expected 3, 4 or 5 channels (u v d [f [ndl]], or R G B [A [5th]]), found " + std::to_string(raw.channels) +
             " channel" + (raw.channels == 1 ? "" : "s"));
  require_float_receivers(raw, path);

  const std::vector<int> order = receiver_channel_order(raw);
  Receivers rec;
  rec.width = raw.width;
  rec.height = raw.height;
  rec.grid = false;
  rec.has_footprint = raw.channels >= 4;
  rec.has_ndl = raw.channels == 5;
  const size_t n = raw.texels();
  rec.u.resize(n);
  rec.v.resize(n);
  rec.d.resize(n);
  rec.f.assign(n, 1.0f);
  if (rec.has_ndl) rec.ndl.resize(n);
  for (size_t t = 0; t < n; ++t) {
    // ndl is carried as stored: a non-finite one means "unknown" and leaves the receiver defined.
    if (rec.has_ndl) rec.ndl[t] = raw.at(t, order[4]);
    rec.u[t] = raw.at(t, order[0]);
    rec.v[t] = raw.at(t, order[1]);
    if (rec.has_footprint) rec.f[t] = raw.at(t, order[3]);
    const float d = raw.at(t, order[2]);
    const bool defined =
        std::isfinite(rec.u[t]) && std::isfinite(rec.v[t]) && std::isfinite(rec.f[t]) && std::isfinite(d);
    rec.d[t] = defined ? static_cast<float>(clamp01(d)) : kNaN;
  }
  return rec;
}

Receivers load_receiver_depth(const std::string& path, int expected_w, int expected_h, const DepthLoadOptions& opt) {
  require_valid_planes(opt, path, kReceiverDepthRole);
  const RawImage raw = read_raw(path, kReceiverDepthRole);
  if (raw.width != expected_w || raw.height != expected_h)
    fail(kReceiverDepthRole, path,
         "size " + size_text(raw.width, raw.height) + " differs from the shadow map's " +
             size_text(expected_w, expected_h) + "; --receiver-depth must match the shadow map");
  Receivers rec;
  rec.width = raw.width;
  rec.height = raw.height;
  rec.grid = true;
  rec.has_footprint = false;
  rec.d = linearize_all(single_depth_channel(raw, path, kReceiverDepthRole), opt);
  return rec;
}

Receivers load_receivers(const std::string& receivers, const std::string& receiver_depth, const HostImage& depth,
                         const DepthLoadOptions& opt) {
  return receivers.empty() ? load_receiver_depth(receiver_depth, depth.width, depth.height, opt)
                           : load_receiver_image(receivers);
}

}  // namespace sf::io

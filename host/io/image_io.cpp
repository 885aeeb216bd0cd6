// Reading shadow maps and receivers (methods.md sec. 1). Writing lives in image_write.cpp.
#include "image_io.hpp"

#include "shadowfilter/footprint.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "depth_decode.hpp"
#include "exr_header.hpp"
#include "png_header.hpp"
#include "image_bounds.hpp"
#include "input_file.hpp"
#include "io_detail.hpp"
#include "output_file.hpp"

namespace sf::io {
namespace {

using detail::check_declared_image_size;
using detail::check_exr_header;
using detail::details_suffix;
using detail::fail;
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
  std::vector<std::string> names{"u", "v", "d", "f", "ndl", "nx", "ny", "nz", "dudx", "dvdx", "dudy", "dvdy"};
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

// The header of a receiver image written by `shadowfilter receivers` (receiver_header_attributes).
ReceiverHeader read_receiver_header(const RawImage& img) {
  ReceiverHeader h;
  auto find = [&](const char* key) {
    const auto it = img.attributes.find(key);
    return it == img.attributes.end() ? std::string() : it->second;
  };
  h.normalized = find("shadowfilter:d") == "normalized";
  const std::string size = find("shadowfilter:map_size");
  if (std::sscanf(size.c_str(), "%dx%d", &h.map_width, &h.map_height) != 2) h.map_width = h.map_height = 0;
  const std::string near_text = find("shadowfilter:light_near"), far_text = find("shadowfilter:light_far");
  if (!near_text.empty()) h.light_near = std::strtod(near_text.c_str(), nullptr);
  if (!far_text.empty()) h.light_far = std::strtod(far_text.c_str(), nullptr);
  return h;
}

}  // namespace

namespace detail {

// The OpenImageIO reader that a file's first bytes name, "" when they name none of these. A file
// is read by the format its content says, whatever its extension; and a file whose content names
// a format but that format's reader refuses is refused, not handed to every other reader in turn,
// as OIIO::ImageInput::open does (a corrupt PNG then loaded every plugin, DICOM and FITS among
// them: 1.7 s and 2 GB under the sanitizers, which the fuzzer found).
std::string reader_of_magic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(h), sizeof h);
  const size_t n = size_t(in.gcount());
  auto starts = [&](const char* magic, size_t len) { return n >= len && std::memcmp(h, magic, len) == 0; };
  if (starts("v/1\x01", 4)) return "openexr";
  if (starts("\x89PNG\r\n\x1a\n", 8)) return "png";
  if (starts("II*\0", 4) || starts("MM\0*", 4) || starts("II+\0", 4) || starts("MM\0+", 4)) return "tiff";
  if (starts("#?", 2)) return "hdr";
  if (starts("\xff\xd8\xff", 3)) return "jpeg";
  if (n >= 2 && h[0] == 'P' && (std::strchr("123456fF", h[1]) != nullptr) && h[1] != 0) return "pnm";
  return "";
}

std::unique_ptr<OIIO::ImageInput> open_checked_image(const std::string& path, const std::string& role) {
  const uint64_t file_bytes = require_regular_file(path, role);
  record_input(path);
  return with_out_of_memory_named(path, role, [&] {
    const std::string format = reader_of_magic(path);
    if (format == "openexr") check_exr_header(path, file_bytes, role);
    if (format == "png") detail::check_png_chunks(path, file_bytes, role);
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);  // keep stored values: never premultiply
    std::unique_ptr<OIIO::ImageInput> input;
    if (format.empty()) {  // content OIIO knows another way (its readers' own checks decide)
      input = OIIO::ImageInput::open(path, &config);
      if (!input) fail(role, path, "not a readable image" + details_suffix(OIIO::geterror()));
    } else {
      input = OIIO::ImageInput::create(format, /*do_open=*/false, &config);
      if (!input)
        fail(role, path, "not a readable image (no " + format + " reader" + details_suffix(OIIO::geterror()) + ")");
      OIIO::ImageSpec opened;
      if (!input->open(path, opened, config))
        fail(role, path, "not a readable " + format + " image" + details_suffix(input->geterror()));
    }
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

DepthDecoding DepthLoadOptions::decoding() const {
  DepthDecoding d;
  d.encoding = encoding;
  d.near_plane = near_plane;
  d.far_plane = far_plane;
  d.beyond_far_is_empty = beyond_far_is_empty;
  return d;
}

DepthEncoding parse_depth_encoding(const std::string& name) {
  DepthEncoding encoding;
  if (!sf::parse_depth_encoding(name, &encoding))
    throw InputError("unknown depth encoding '" + detail::one_line(name) + "'; valid: " + depth_encoding_names());
  return encoding;
}

double linearize_depth(double stored, const DepthLoadOptions& opt) { return decode_depth(stored, opt.decoding()); }

HostImage load_depth_map(const std::string& path, const DepthLoadOptions& opt) {
  const RawImage raw = read_raw(path, kShadowMapRole);
  detail::require_16_bit_depth(raw, kShadowMapRole, path);
  HostImage depth_map;
  depth_map.width = raw.width;
  depth_map.height = raw.height;
  depth_map.channels = 1;
  depth_map.data = detail::single_depth_channel(raw, path, kShadowMapRole);
  detail::decode_depths(depth_map.data, opt, kShadowMapRole, path, 1.0f, false);
  resolve_nonfinite_depth(depth_map.data, raw, opt, path);
  return depth_map;
}

std::map<std::string, std::string> receiver_header_attributes(int map_width, int map_height, double light_near,
                                                              double light_far) {
  std::ostringstream near_text, far_text;
  near_text.precision(17);
  far_text.precision(17);
  near_text << light_near;
  far_text << light_far;
  return {{"shadowfilter:d", "normalized"},
          {"shadowfilter:map_size", size_text(map_width, map_height)},
          {"shadowfilter:light_near", near_text.str()},
          {"shadowfilter:light_far", far_text.str()}};
}

// Non-finite u, v or f also make a texel background: such a receiver has no defined lookup.
Receivers load_receiver_image(const std::string& path, const DepthLoadOptions& decoding,
                              const std::optional<DepthLoadOptions>& stated, ReceiverHeader* header) {
  const RawImage raw = read_raw(path, kReceiverImageRole);
  const ReceiverHeader facts = read_receiver_header(raw);
  if (header) *header = facts;
  if (raw.channels < 3 || (raw.channels > 5 && raw.channels != 8 && raw.channels != 12))
    fail(kReceiverImageRole, path,
         "expected 3, 4, 5, 8 or 12 channels (u v d [f [ndl [nx ny nz [dudx dvdx dudy dvdy]]]], or R G B [A [5th "
         "[6th-8th [9th-12th]]]]), found " +
             std::to_string(raw.channels) + " channel" + (raw.channels == 1 ? "" : "s"));
  require_float_receivers(raw, path);

  const std::vector<int> order = receiver_channel_order(raw);
  Receivers rec;
  rec.width = raw.width;
  rec.height = raw.height;
  rec.grid = false;
  rec.has_footprint = raw.channels >= 4;
  rec.has_ndl = raw.channels >= 5;
  rec.has_normal = raw.channels >= 8;
  rec.has_jacobian = raw.channels == 12;
  const size_t n = raw.texels();
  rec.u.resize(n);
  rec.v.resize(n);
  rec.d.resize(n);
  rec.f.assign(n, 1.0f);
  if (rec.has_ndl) rec.ndl.resize(n);
  if (rec.has_normal) {
    rec.nx.resize(n);
    rec.ny.resize(n);
    rec.nz.resize(n);
  }
  if (rec.has_jacobian) {
    rec.dudx.resize(n);
    rec.dvdx.resize(n);
    rec.dudy.resize(n);
    rec.dvdy.resize(n);
  }
  std::vector<float> stored_d(n);
  for (size_t t = 0; t < n; ++t) stored_d[t] = raw.at(t, order[2]);
  // d as the user states it, else as the file's header says (d itself), else as the map's.
  DepthLoadOptions d_decoding = stated ? *stated : decoding;
  if (!stated && facts.normalized) {
    d_decoding = DepthLoadOptions{};
    d_decoding.flag = "d in [0, 1] (its header says shadowfilter:d normalized)";
  }
  // nz is a step of the normalized depth the filter compares: a d stored in another encoding
  // (world units, window depth) would need it converted at every receiver, which the file cannot say.
  if (rec.has_normal && !(d_decoding.encoding == DepthEncoding::Linear && !std::isfinite(d_decoding.near_plane) &&
                          !std::isfinite(d_decoding.far_plane)))
    fail(kReceiverImageRole, path,
         std::string("nx ny nz need d stored as normalized linear depth in [0, 1] (nz is a step of it), but d "
                     "is decoded as ") +
             depth_encoding_name(d_decoding.encoding) +
             (std::isfinite(d_decoding.near_plane) ? " with near and far planes" : "") + " (" + d_decoding.flag +
             "); drop the normal channels or store d normalized");
  detail::decode_depths(stored_d, d_decoding, kReceiverImageRole, path, kNaN, true);
  for (size_t t = 0; t < n; ++t) {
    // ndl is carried as stored: a non-finite one means "unknown" and leaves the receiver defined.
    if (rec.has_ndl) rec.ndl[t] = raw.at(t, order[4]);
    // So is the normal: a non-finite component means "unknown", no offset (normal_offset.hpp).
    if (rec.has_normal) {
      rec.nx[t] = raw.at(t, order[5]);
      rec.ny[t] = raw.at(t, order[6]);
      rec.nz[t] = raw.at(t, order[7]);
    }
    rec.u[t] = raw.at(t, order[0]);
    rec.v[t] = raw.at(t, order[1]);
    if (rec.has_footprint) rec.f[t] = raw.at(t, order[3]);
    if (rec.has_jacobian) {
      rec.dudx[t] = raw.at(t, order[8]);
      rec.dvdx[t] = raw.at(t, order[9]);
      rec.dudy[t] = raw.at(t, order[10]);
      rec.dvdy[t] = raw.at(t, order[11]);
    }
    const float d = stored_d[t];
    const bool defined =
        std::isfinite(rec.u[t]) && std::isfinite(rec.v[t]) && std::isfinite(rec.f[t]) && std::isfinite(d);
    rec.d[t] = defined ? d : kNaN;
  }
  isotropic_where_unknown(rec);  // a non-finite Jacobian is unknown (footprint.hpp)
  return rec;
}

Receivers load_receiver_depth(const std::string& path, int expected_w, int expected_h, const DepthLoadOptions& opt) {
  const RawImage raw = read_raw(path, kReceiverDepthRole);
  detail::require_16_bit_depth(raw, kReceiverDepthRole, path);
  if (raw.width != expected_w || raw.height != expected_h)
    fail(kReceiverDepthRole, path,
         "size " + size_text(raw.width, raw.height) + " differs from the shadow map's " +
             size_text(expected_w, expected_h) + "; --receiver-depth must match the shadow map");
  Receivers rec;
  rec.width = raw.width;
  rec.height = raw.height;
  rec.grid = true;
  rec.has_footprint = false;
  rec.d = detail::single_depth_channel(raw, path, kReceiverDepthRole);
  detail::decode_depths(rec.d, opt, kReceiverDepthRole, path, kNaN, true);
  return rec;
}

Receivers load_receivers(const std::string& receivers, const std::string& receiver_depth, const HostImage& depth,
                         const DepthLoadOptions& opt, const std::optional<DepthLoadOptions>& stated,
                         ReceiverHeader* header) {
  if (header) *header = ReceiverHeader{};
  return receivers.empty() ? load_receiver_depth(receiver_depth, depth.width, depth.height, stated ? *stated : opt)
                           : load_receiver_image(receivers, opt, stated, header);
}

}  // namespace sf::io

// Stored depth -> d with a range check (depth_decode.hpp).
#include "depth_decode.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>

namespace sf::io::detail {
namespace {

std::string number(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::string range_text(double lo, double hi) { return "[" + number(lo) + ", " + number(hi) + "]"; }

// How the values were read: "--encoding perspective --near 1 --far 20", or the flag's own text
// when it is not a flag (a file header's statement).
std::string encoding_text(const DepthLoadOptions& o, const DepthDecoding& d, bool receivers) {
  if (o.flag.empty() || o.flag[0] != '-') return o.flag;
  std::string text = o.flag + " " + depth_encoding_name(d.encoding);
  if (has_planes(d)) text += " --near " + number(d.near_plane) + " --far " + number(d.far_plane);
  if (receivers && o.flag == "--encoding") text += ", the map's";
  return text;
}

// The likely cause of values [lo, hi] outside `range`, and its fix.
std::string hint(double lo, double hi, const StoredRange& range, const DepthLoadOptions& o, const DepthDecoding& d,
                 bool receivers) {
  const std::string flag = receivers ? "--receiver-encoding" : "--encoding";
  const double slack = 1e-3;
  const bool unit = lo >= -slack && hi <= 1.0 + slack;
  const bool ndc_like = lo < 0.0 && lo >= -1.0 - slack && hi <= 1.0 + slack;
  const std::string normalized =
      receivers ? " (receivers written by `shadowfilter receivers` or `scene` hold d itself: " + flag + " normalized)"
                : "";
  switch (d.encoding) {
    case DepthEncoding::Linear:
      if (!has_planes(d)) {
        if (ndc_like) return "OpenGL NDC z in [-1, 1]? " + flag + " perspective-ndc with the light's --near and --far";
        return "linear depth in world units? Give the light's planes: " + flag + " linear --near N --far F";
      }
      if (unit && range.lo > 1.0 + slack)
        return "d in [0, 1] or window depth? Drop --near/--far, or " + flag + " perspective" + normalized;
      if (hi > range.hi)
        return "deeper than --far " + number(range.hi) +
               ": is --far the light's far plane? (a renderer's value for nothing hit, such as Blender's 1e10: "
               "--beyond-far far)";
      return "nearer than --near " + number(range.lo) + ": is --near the light's near plane?" + normalized;
    case DepthEncoding::PerspectiveNdc:
      return "linear depth in world units? " + flag + " linear --near N --far F";
    case DepthEncoding::ReversedInfinite:
      if (unit) return "deeper than --far " + number(d.far_plane) + ": a larger --far, or --beyond-far far";
      return "window depth lies in [0, 1]; world units? " + flag + " linear --near N --far F";
    default:
      if (ndc_like) return "OpenGL NDC z in [-1, 1]? " + flag + " perspective-ndc";
      return "window depth lies in [0, 1]; linear depth in world units? " + flag + " linear --near N --far F";
  }
}

bool same_value(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }

std::string texel_text(const RawImage& img, size_t texel) {
  return "(x=" + std::to_string(texel % size_t(img.width)) + ", y=" + std::to_string(texel / size_t(img.width)) + ")";
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string channel_list(const RawImage& img) {
  std::string names;
  for (const std::string& n : img.channel_names) names += (names.empty() ? "" : " ") + n;
  return names;
}

}  // namespace

std::vector<float> single_depth_channel(const RawImage& img, const std::string& path, const std::string& role) {
  if (img.channels == 1) return img.pixels;
  std::vector<int> named;
  for (int c = 0; c < int(img.channel_names.size()); ++c) {
    const std::string& n = img.channel_names[size_t(c)];
    if (n == "Z" || n == "depth" || ends_with(n, ".Z")) named.push_back(c);
  }
  if (named.size() == 1) {
    std::vector<float> depth(img.texels());
    for (size_t t = 0; t < img.texels(); ++t) depth[t] = img.at(t, named[0]);
    return depth;
  }
  if (img.channels != 3 && img.channels != 4)
    fail(role, path,
         "expected 1 channel, one named Z, or 3-4 channels with identical first three; found " +
             std::to_string(img.channels) + " channels (" + channel_list(img) + ")");
  std::vector<float> depth(img.texels());
  for (size_t t = 0; t < img.texels(); ++t) {
    const float first = img.at(t, 0);
    if (!same_value(first, img.at(t, 1)) || !same_value(first, img.at(t, 2)))
      fail(role, path,
           "expected 1 channel, one named Z, or 3-4 channels with identical first three; found " +
               std::to_string(img.channels) + " channels that differ at " + texel_text(img, t));
    depth[t] = first;
  }
  return depth;
}

std::vector<int> three_channels(const RawImage& img, const std::vector<std::vector<std::string>>& names,
                                const std::string& path, const std::string& role) {
  for (const std::vector<std::string>& triple : names) {
    std::vector<int> found;
    for (const std::string& n : triple)
      for (int c = 0; c < int(img.channel_names.size()); ++c)
        if (img.channel_names[size_t(c)] == n) {
          found.push_back(c);
          break;
        }
    if (found.size() == 3) return found;
  }
  if (img.channels == 3 || img.channels == 4) return {0, 1, 2};
  fail(role, path,
       "expected 3 channels (x y z), or 4 with the 4th ignored; found " + std::to_string(img.channels) + " (" +
           channel_list(img) + ")");
}

void require_16_bit_depth(const RawImage& img, const std::string& role, const std::string& path) {
  const OIIO::TypeDesc t = img.stored_format;
  if (t.is_floating_point() || t.size() >= 2) return;
  fail(role, path,
       std::string("depth stored in ") + t.c_str() +
           " (8 bits: 256 depth levels, far too coarse for depth tests); save it with 16 bits (16-bit PNG or "
           "TIFF) or as float (EXR, TIFF, PFM)");
}

void decode_depths(std::vector<float>& values, const DepthLoadOptions& opt, const std::string& role,
                   const std::string& path, float empty, bool receivers) {
  const DepthDecoding d = opt.decoding();
  try {
    validate(d);
  } catch (const InputError& e) {
    fail(role, path, e.what());
  }
  const StoredRange range = stored_range(d);
  const double scale = std::max(std::fabs(range.lo), std::fabs(range.hi));
  const double tolerance = 1e-6 * (range.hi - range.lo) + 4.0 * FLT_EPSILON * scale;
  const bool infinite = d.encoding == DepthEncoding::ReversedInfinite;
  // Past the far plane: above hi, or below lo for the reversed encodings (their far end is lo).
  const bool far_is_low =
      d.encoding == DepthEncoding::Reversed || infinite || d.encoding == DepthEncoding::ReversedLinear;
  double lo = INFINITY, hi = -INFINITY;
  size_t bad = 0;
  for (float& value : values) {
    if (!std::isfinite(value)) {
      value = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    double w = value;
    lo = std::min(lo, w), hi = std::max(hi, w);
    if (infinite && w == 0.0) {
      value = empty;  // infinitely far: nothing hit
      continue;
    }
    const bool beyond_far = far_is_low ? w < range.lo - tolerance : w > range.hi + tolerance;
    if (beyond_far && d.beyond_far_is_empty) {
      value = empty;
      continue;
    }
    if (w < range.lo - tolerance || w > range.hi + tolerance) {
      ++bad;
      continue;
    }
    w = std::clamp(w, range.lo, range.hi);
    value = static_cast<float>(std::clamp(decode_depth(w, d), 0.0, 1.0));
  }
  if (bad == 0) return;
  const StoredRange shown = infinite ? StoredRange{0.0, 1.0} : range;
  fail(role, path,
       "depths span " + range_text(lo, hi) + ", outside " + range_text(shown.lo, shown.hi) + " of " +
           encoding_text(opt, d, receivers) + " (" + std::to_string(bad) + " value" + (bad == 1 ? "" : "s") + "); " +
           hint(lo, hi, range, opt, d, receivers) + " (docs/inputs.md)");
}

}  // namespace sf::io::detail

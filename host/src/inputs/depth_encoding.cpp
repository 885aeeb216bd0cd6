// Stored depth -> the filter's d (depth_encoding.hpp). Every formula below is
// d = (z - N) / (F - N) with z the distance along the axis that the stored value w stands for,
// rearranged so that no large z is formed on the way (w near the far plane loses no digits).
#include "shadowfilter/depth_encoding.hpp"

#include <cmath>
#include <sstream>

#include "shadowfilter/errors.hpp"

namespace sf {
namespace {

struct NamedEncoding {
  DepthEncoding encoding;
  const char* name;
};
constexpr NamedEncoding kEncodings[] = {
    {DepthEncoding::Linear, "linear"},
    {DepthEncoding::Perspective, "perspective"},
    {DepthEncoding::PerspectiveNdc, "perspective-ndc"},
    {DepthEncoding::Reversed, "reversed"},
    {DepthEncoding::ReversedInfinite, "reversed-infinite"},
    {DepthEncoding::ReversedLinear, "reversed-linear"},
};

std::string planes_text(const DepthDecoding& d) {
  std::ostringstream s;
  s << "near=" << d.near_plane << ", far=" << d.far_plane;
  return s.str();
}

}  // namespace

const char* depth_encoding_name(DepthEncoding encoding) {
  for (const NamedEncoding& e : kEncodings)
    if (e.encoding == encoding) return e.name;
  return "?";
}

bool parse_depth_encoding(const std::string& name, DepthEncoding* encoding) {
  for (const NamedEncoding& e : kEncodings)
    if (name == e.name) {
      *encoding = e.encoding;
      return true;
    }
  return false;
}

std::string depth_encoding_names() {
  std::string names;
  for (const NamedEncoding& e : kEncodings) names += (names.empty() ? "" : ", ") + std::string(e.name);
  return names;
}

bool has_planes(const DepthDecoding& d) { return !std::isnan(d.near_plane) || !std::isnan(d.far_plane); }

void validate(const DepthDecoding& d) {
  const std::string name = depth_encoding_name(d.encoding);
  const bool near_given = !std::isnan(d.near_plane), far_given = !std::isnan(d.far_plane);
  const bool planes_optional = d.encoding == DepthEncoding::Linear || d.encoding == DepthEncoding::ReversedLinear;
  if (planes_optional && !near_given && !far_given) {
    if (d.beyond_far_is_empty)
      throw InputError("DepthDecoding::beyond_far_is_empty needs world units (" + name +
                       " depth in [0, 1] has nothing beyond its far plane)");
    return;
  }
  if (!near_given || !far_given)
    throw InputError(
        std::string(d.encoding == DepthEncoding::Linear ? "linear depth in world units" : name + " depth") +
        " needs both DepthDecoding::near_plane and DepthDecoding::far_plane (the light's planes, world units "
        "along its axis); no defaults are assumed");
  if (!std::isfinite(d.near_plane) || !std::isfinite(d.far_plane) || !(d.near_plane < d.far_plane))
    throw InputError(name + " depth needs finite DepthDecoding::near_plane < DepthDecoding::far_plane (got " +
                     planes_text(d) + ")");
  const bool perspective = d.encoding != DepthEncoding::Linear && d.encoding != DepthEncoding::ReversedLinear;
  if (perspective && !(d.near_plane > 0.0))
    throw InputError(name + " depth needs DepthDecoding::near_plane > 0 (a perspective projection's near plane; got " +
                     planes_text(d) + ")");
}

StoredRange stored_range(const DepthDecoding& d) {
  switch (d.encoding) {
    case DepthEncoding::Linear:
      return has_planes(d) ? StoredRange{d.near_plane, d.far_plane} : StoredRange{0.0, 1.0};
    case DepthEncoding::PerspectiveNdc:
      return {-1.0, 1.0};
    case DepthEncoding::ReversedInfinite:
      return {d.near_plane / d.far_plane, 1.0};
    default:
      return {0.0, 1.0};
  }
}

double decode_depth(double stored, const DepthDecoding& decoding) {
  if (!std::isfinite(stored)) return std::numeric_limits<double>::quiet_NaN();
  double w = stored;
  const double n = decoding.near_plane, f = decoding.far_plane;
  switch (decoding.encoding) {
    case DepthEncoding::Linear:
      return has_planes(decoding) ? (w - n) / (f - n) : w;
    case DepthEncoding::PerspectiveNdc:
      w = 0.5 * (w + 1.0);
      [[fallthrough]];
    case DepthEncoding::Perspective:
      // z = N F / (F - w (F - N))  =>  d = N w / (F - w (F - N))
      return n * w / (f - w * (f - n));
    case DepthEncoding::Reversed:
      // z = N F / (N + w (F - N))  =>  d = N (1 - w) / (N + w (F - N))
      return n * (1.0 - w) / (n + w * (f - n));
    case DepthEncoding::ReversedInfinite:
      // z = N / w  =>  d = N (1 - w) / (w (F - N)); w = 0 is infinitely far: nothing hit
      return w == 0.0 ? 1.0 : n * (1.0 - w) / (w * (f - n));
    case DepthEncoding::ReversedLinear:
      return 1.0 - w;
  }
  return w;
}

}  // namespace sf

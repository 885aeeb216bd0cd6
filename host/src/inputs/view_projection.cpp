// What a view and projection say about depth (view_projection.hpp).
#include "shadowfilter/view_projection.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "matrix4.hpp"
#include "shadowfilter/errors.hpp"

namespace sf {
namespace {

std::string row_text(const std::array<double, 16>& m, int row) {
  std::ostringstream s;
  const size_t r = size_t(row) * 4;
  s << "(" << m[r] << " " << m[r + 1] << " " << m[r + 2] << " " << m[r + 3] << ")";
  return s.str();
}

const char* const kTransposed = ": a column-major (transposed) matrix? The files hold rows first";

void require_finite(const std::array<double, 16>& m, const char* name) {
  for (double v : m)
    if (!std::isfinite(v)) throw InputError(std::string(name) + " holds a non-finite number");
}

// The view's last row is (0 0 0 1): an affine map of world to view space.
void require_affine_view(const std::array<double, 16>& v) {
  const double scale = std::fmax(1.0, std::fabs(v[15]));
  if (std::fabs(v[12]) > 1e-9 * scale || std::fabs(v[13]) > 1e-9 * scale || std::fabs(v[14]) > 1e-9 * scale ||
      std::fabs(v[15] - 1.0) > 1e-9)
    throw InputError("the view matrix's last row is " + row_text(v, 3) + ", not (0 0 0 1)" + kTransposed);
}

}  // namespace

const char* clip_space_name(ClipSpace clip) {
  switch (clip) {
    case ClipSpace::OpenGL:
      return "opengl";
    case ClipSpace::D3D:
      return "d3d";
    case ClipSpace::Vulkan:
      return "vulkan";
  }
  return "?";
}

ProjectionDepth projection_depth(const ViewProjection& vp) {
  require_finite(vp.view, "the view matrix");
  require_finite(vp.projection, "the projection matrix");
  require_affine_view(vp.view);
  detail::Mat4 inverse;
  if (!detail::invert(vp.view, &inverse)) throw InputError("the view matrix is singular (no inverse)");
  if (!detail::invert(vp.projection, &inverse)) throw InputError("the projection matrix is singular (no inverse)");
  const std::array<double, 16>& p = vp.projection;
  // Depth (rows 3 and 4) must depend on view z alone: z_ndc = (a z + b) / (c z + e).
  if (p[8] != 0.0 || p[9] != 0.0 || p[12] != 0.0 || p[13] != 0.0)
    throw InputError("the projection's third or fourth row depends on x or y (rows " + row_text(p, 2) + ", " +
                     row_text(p, 3) + "); only standard perspective and orthographic projections are read" +
                     kTransposed);
  const double a = p[10], b = p[11], c = p[14], e = p[15];
  ProjectionDepth pd;
  if (c != 0.0 && e == 0.0) {
    pd.perspective = true;
  } else if (c == 0.0 && e != 0.0) {
    pd.perspective = false;
  } else {
    throw InputError("the projection's last row " + row_text(p, 3) +
                     " is neither perspective (0 0 c 0) nor orthographic (0 0 0 e)" + kTransposed);
  }
  if (pd.perspective && std::fabs(std::fabs(b) - 1.0) < 1e-12 && std::fabs(std::fabs(c) - 1.0) > 1e-6)
    throw InputError("the projection's rows 3 and 4 are " + row_text(p, 2) + ", " + row_text(p, 3) +
                     ": the -1 of a perspective projection belongs in row 4 (0 0 -1 0)" + kTransposed);
  const double lo = vp.clip == ClipSpace::OpenGL ? -1.0 : 0.0, hi = 1.0;
  // View z where z_ndc takes a value (infinite where the value is the projection's limit).
  auto view_z = [&](double ndc) {
    const double den = pd.perspective ? ndc * c - a : a;
    const double num = pd.perspective ? b - ndc * e : ndc * e - b;
    return den == 0.0 ? std::copysign(INFINITY, num) : num / den;
  };
  const double z_lo = view_z(lo), z_hi = view_z(hi);
  if (pd.perspective) {
    pd.forward = c > 0.0 ? 1.0 : -1.0;  // w_clip = c z > 0 in front of the eye
    const double d_lo = pd.forward * z_lo, d_hi = pd.forward * z_hi;
    pd.reversed = std::isinf(d_lo) || (std::isfinite(d_hi) && d_hi < d_lo);
    pd.near_plane = pd.reversed ? d_hi : d_lo;
    const double far = pd.reversed ? d_lo : d_hi;
    pd.infinite_far = std::isinf(far) || std::fabs(far) > 1e300;
    pd.far_plane = far;
    if (std::isinf(pd.near_plane) || !(pd.near_plane > 0.0) || (!pd.infinite_far && !(far > pd.near_plane))) {
      std::ostringstream s;
      s << "the projection maps " << clip_space_name(vp.clip) << " clip depth to distances " << d_lo << " .. " << d_hi
        << " along its axis, not a near plane > 0 and a farther far plane (is \"clip\" the renderer's?)";
      throw InputError(s.str());
    }
    if (vp.reversed_z && *vp.reversed_z != pd.reversed)
      throw InputError(std::string("\"reversed_z\" is ") + (*vp.reversed_z ? "true" : "false") +
                       " but the projection maps its near plane to window depth " + (pd.reversed ? "1" : "0") +
                       (pd.reversed ? " (reversed-Z)" : " (conventional)"));
  } else {
    pd.reversed = vp.reversed_z.value_or(false);
    const double z_near = pd.reversed ? z_hi : z_lo, z_far = pd.reversed ? z_lo : z_hi;
    pd.forward = z_far > z_near ? 1.0 : -1.0;
    pd.near_plane = pd.forward * z_near;
    pd.far_plane = pd.forward * z_far;
  }
  if (pd.infinite_far) {
    if (!pd.reversed)
      throw InputError("the projection has an infinite far plane without reversed-Z; only reversed-Z ones are read");
    if (!std::isnan(vp.infinite_far_depth) &&
        (!std::isfinite(vp.infinite_far_depth) || !(vp.infinite_far_depth > pd.near_plane))) {
      std::ostringstream s;
      s << "ViewProjection::infinite_far_depth must be finite and beyond the near plane " << pd.near_plane << ", got "
        << vp.infinite_far_depth;
      throw InputError(s.str());
    }
    pd.far_plane = std::isnan(vp.infinite_far_depth) ? INFINITY : vp.infinite_far_depth;
  } else if (!std::isnan(vp.infinite_far_depth)) {
    std::ostringstream s;
    s << "ViewProjection::infinite_far_depth is for an infinite far plane; this projection's far plane is at "
      << pd.far_plane;
    throw InputError(s.str());
  }
  return pd;
}

ProjectionDepth light_projection_depth(const ViewProjection& light) {
  ProjectionDepth pd = projection_depth(light);
  if (!std::isfinite(pd.far_plane)) {
    std::ostringstream s;
    s << "the light's projection has an infinite far plane: give ViewProjection::infinite_far_depth, the depth along "
         "its axis that becomes d = 1 (finite, beyond the near plane "
      << pd.near_plane << ")";
    throw InputError(s.str());
  }
  return pd;
}

DepthDecoding window_depth_decoding(const ViewProjection& light) {
  const ProjectionDepth pd = light_projection_depth(light);
  DepthDecoding d;
  if (!pd.perspective) {
    d.encoding = pd.reversed ? DepthEncoding::ReversedLinear : DepthEncoding::Linear;
    if (pd.reversed) {
      d.near_plane = pd.near_plane;
      d.far_plane = pd.far_plane;
    }
    return d;
  }
  d.encoding = pd.infinite_far ? DepthEncoding::ReversedInfinite
                               : (pd.reversed ? DepthEncoding::Reversed : DepthEncoding::Perspective);
  d.near_plane = pd.near_plane;
  d.far_plane = pd.far_plane;
  return d;
}

}  // namespace sf

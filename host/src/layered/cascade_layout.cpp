// Cascade sets: the layer transform, validation, the selection rule and the layout fits
// (cascades.hpp; methods.md sec. 6).
#include <algorithm>
#include <cmath>
#include <limits>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/errors.hpp"

namespace sf {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Stabilised layers move in steps of this many texels: mip levels 0..5 keep their texel blocks.
constexpr int kStableSnapTexels = 32;

// Row r of the matrix as (xyz, constant).
Point3 row_xyz(const LayerTransform& t, int r) { return {t.m[4 * r], t.m[4 * r + 1], t.m[4 * r + 2]}; }
double row_at(const LayerTransform& t, int r, const Point3& p) { return dot(row_xyz(t, r), p) + t.m[4 * r + 3]; }

// Solves A x = b (3x3, row-major) by Cramer's rule; false when |det| is negligible against the
// rows' scale.
bool solve3(const std::array<Point3, 3>& a, const Point3& b, Point3& x) {
  const double det = dot(a[0], cross(a[1], a[2]));
  const double scale = length(a[0]) * length(a[1]) * length(a[2]);
  if (!(std::abs(det) > 1e-12 * scale) || !std::isfinite(det)) return false;
  // Columns of the inverse: cross products of the rows.
  const Point3 c0 = cross(a[1], a[2]), c1 = cross(a[2], a[0]), c2 = cross(a[0], a[1]);
  for (int i = 0; i < 3; ++i) x[i] = (c0[i] * b[0] + c1[i] * b[1] + c2[i] * b[2]) / det;
  return true;
}

// The light's axes, the convention of the scene generator (scene_views.cpp): "down" in the map is
// world +z projected onto the image plane (world +x when the light looks along z), right = down x
// forward.
struct LightAxes {
  Point3 right, down, forward;
};
LightAxes light_axes(const Point3& direction) {
  LightAxes axes;
  axes.forward = normalize(direction);
  Point3 ref{0, 0, 1};
  if (std::abs(dot(ref, axes.forward)) > 0.99) ref = {1, 0, 0};
  axes.down = normalize((ref - (dot(ref, axes.forward) * axes.forward)));
  axes.right = cross(axes.down, axes.forward);
  return axes;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double x) {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  bool overlaps(const Range& o) const { return lo <= o.hi && o.lo <= hi; }
};

// Depths (along forward) of the part of `box` inside the light's prism over x * y (the light-space
// rectangle, infinite along forward): B and the prism are convex, so the extremes lie at vertices
// of their intersection, which are box corners inside the prism, box edges crossing the prism's
// sides, or the prism's edges crossing the box's faces. Empty when they do not meet. Exact where
// a box's rectangle is far larger than the layer's (a ground plane under a near cascade).
Range clipped_depths(const WorldBox& box, const LightAxes& axes, const Range& x, const Range& y) {
  const double tol = 1e-9 * std::max({1.0, std::abs(x.lo), std::abs(x.hi), std::abs(y.lo), std::abs(y.hi)});
  const auto in_prism = [&](const Point3& p) {
    const double px = dot(p, axes.right), py = dot(p, axes.down);
    return px >= x.lo - tol && px <= x.hi + tol && py >= y.lo - tol && py <= y.hi + tol;
  };
  const auto in_box = [&](const Point3& p) {
    for (int i = 0; i < 3; ++i) {
      const double t = 1e-9 * std::max({1.0, std::abs(box.lo[i]), std::abs(box.hi[i])});
      if (p[i] < box.lo[i] - t || p[i] > box.hi[i] + t) return false;
    }
    return true;
  };
  Range z;
  const auto corner = [&](int k) {
    return Point3{(k & 1) ? box.hi[0] : box.lo[0], (k & 2) ? box.hi[1] : box.lo[1], (k & 4) ? box.hi[2] : box.lo[2]};
  };
  for (int k = 0; k < 8; ++k)
    if (in_prism(corner(k))) z.add(dot(corner(k), axes.forward));
  // Box edges (corner pairs differing in one bit) against the prism's four side planes.
  const std::array<std::pair<const Point3*, double>, 4> sides{
      {{&axes.right, x.lo}, {&axes.right, x.hi}, {&axes.down, y.lo}, {&axes.down, y.hi}}};
  for (int k = 0; k < 8; ++k)
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (k & bit) continue;
      const Point3 a = corner(k), b = corner(k | bit);
      for (const auto& [axis, level] : sides) {
        const double fa = dot(a, *axis) - level, fb = dot(b, *axis) - level;
        if ((fa < 0) == (fb < 0) || fa == fb) continue;
        const Point3 p = (a + (fa / (fa - fb) * (b - a)));
        if (in_prism(p)) z.add(dot(p, axes.forward));
      }
    }
  // The prism's four edges (lines along forward) against the box's six faces.
  for (double px : {x.lo, x.hi})
    for (double py : {y.lo, y.hi}) {
      const Point3 origin = ((px * axes.right) + (py * axes.down));
      for (int i = 0; i < 3; ++i) {
        if (axes.forward[i] == 0.0) continue;
        for (double face : {box.lo[i], box.hi[i]}) {
          const double t = (face - origin[i]) / axes.forward[i];
          const Point3 p = (origin + (t * axes.forward));
          if (in_box(p)) z.add(t);
        }
      }
    }
  return z;
}

// A layer's depth range: the parts of the scene's boxes inside the light's prism over the layer
// can cast or receive in it; nothing lies beyond the deepest point of the slice that reaches its
// receivers. Widened by 1% and a small absolute margin, as the scene's maps are.
Range layer_depths(const LightAxes& axes, const Range& x, const Range& y, const std::array<Point3, 8>& slice,
                   const std::vector<WorldBox>& geometry) {
  Range z, slice_z;
  for (const Point3& c : slice) slice_z.add(dot(c, axes.forward));
  for (const WorldBox& box : geometry) {
    const Range part = clipped_depths(box, axes, x, y);
    if (part.lo <= part.hi) z.add(part.lo), z.add(part.hi);
  }
  if (!(z.lo <= z.hi)) z = slice_z;
  z.hi = std::min(z.hi, slice_z.hi);
  z.lo = std::min(z.lo, z.hi);
  const double pad = 0.01 * (z.hi - z.lo) + 1e-6 * std::max({1.0, std::abs(z.lo), std::abs(z.hi)});
  z.lo -= pad;
  z.hi += pad;
  return z;
}

// The orthographic layer of the light-space rectangle x * y and depths z.
LayerTransform ortho_layer(const LightAxes& axes, const Range& x, const Range& y, const Range& z) {
  LayerTransform t;
  const auto set_row = [&](int r, const Point3& axis, const Range& range) {
    const double s = 1.0 / (range.hi - range.lo);
    for (int i = 0; i < 3; ++i) t.m[4 * r + i] = s * axis[i];
    t.m[4 * r + 3] = -range.lo * s;
  };
  set_row(0, axes.right, x);
  set_row(1, axes.down, y);
  set_row(2, axes.forward, z);
  t.m[12] = t.m[13] = t.m[14] = 0.0;
  t.m[15] = 1.0;
  return t;
}

// Minimal sphere around a symmetric frustum slice [a, b] (corner half-diagonal k * depth): its
// centre's view depth and radius. Depends on the slice's shape only, not on where the camera looks.
void slice_sphere(double a, double b, double k, double& centre, double& radius) {
  const double ra = a * k, rb = b * k;
  centre = (b * b + rb * rb - a * a - ra * ra) / (2.0 * (b - a));
  centre = std::clamp(centre, a, b);
  radius = std::max(std::hypot(centre - a, ra), std::hypot(b - centre, rb));
}

// 3x3 homography taking src[i] to dst[i] (i = 0..3), row-major, by an 8x8 solve.
std::array<double, 9> homography(const std::array<std::array<double, 2>, 4>& src,
                                 const std::array<std::array<double, 2>, 4>& dst) {
  double a[8][9] = {};
  for (int i = 0; i < 4; ++i) {
    const double x = src[i][0], y = src[i][1], u = dst[i][0], v = dst[i][1];
    double* r0 = a[2 * i];
    double* r1 = a[2 * i + 1];
    r0[0] = x, r0[1] = y, r0[2] = 1, r0[6] = -u * x, r0[7] = -u * y, r0[8] = u;
    r1[3] = x, r1[4] = y, r1[5] = 1, r1[6] = -v * x, r1[7] = -v * y, r1[8] = v;
  }
  for (int c = 0; c < 8; ++c) {
    int pivot = c;
    for (int r = c + 1; r < 8; ++r)
      if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
    if (!(std::abs(a[pivot][c]) > 1e-300)) throw InputError("the trapezoid of a tsm layer is degenerate");
    std::swap(a[c], a[pivot]);
    for (int r = 0; r < 8; ++r) {
      if (r == c) continue;
      const double f = a[r][c] / a[c][c];
      for (int k = c; k < 9; ++k) a[r][k] -= f * a[c][k];
    }
  }
  std::array<double, 9> h{};
  for (int i = 0; i < 8; ++i) h[i] = a[i][8] / a[i][i];
  h[8] = 1.0;
  return h;
}

struct Slice {
  double a = 0, b = 0;
};

CascadeLayer fit_uniform(const LayoutOptions& o, const CameraFrustum& cam, const LightAxes& axes, Slice s,
                         const std::vector<WorldBox>& geometry) {
  const auto corners = cam.slice_corners(s.a, s.b);
  Range x, y;
  if (o.stabilize) {
    const double tan_half = std::tan(0.5 * cam.vertical_fov_degrees * kPi / 180.0);
    const double k = tan_half * std::sqrt(1.0 + cam.aspect * cam.aspect);
    double centre_depth = 0, radius = 0;
    slice_sphere(s.a, s.b, k, centre_depth, radius);
    const Point3 centre = (cam.position + (centre_depth * cam.forward));
    // The map moves in steps of `snap` texels along the light's axes: a static texel grid in
    // world space, and static mip levels too up to log2(snap) (a one-texel step regroups every
    // 2x2 block of the mips: evaluate-layouts measured it as the whole of treeline's residual
    // flicker). The centre moves up to snap/2 texels off the sphere's, so the square is that much
    // wider than the sphere: texel = 2 r / (size - snap).
    const int snap = std::min(kStableSnapTexels, std::max(1, o.map_size / 8));
    const double texel = 2.0 * radius / (o.map_size - snap);
    const double half = 0.5 * texel * o.map_size, step = snap * texel;
    const double cx = std::round(dot(centre, axes.right) / step) * step;
    const double cy = std::round(dot(centre, axes.down) / step) * step;
    x = {cx - half, cx + half};
    y = {cy - half, cy + half};
  } else {
    for (const Point3& c : corners) x.add(dot(c, axes.right)), y.add(dot(c, axes.down));
  }
  Range z = layer_depths(axes, x, y, corners, geometry);
  if (o.stabilize) {
    // The depth range on a coarse grid too (a power of two near an eighth of the range): the
    // stored depths, and the biases and exponents applied to them, change only when the range
    // crosses a grid line, not every frame.
    const double step = std::exp2(std::ceil(std::log2((z.hi - z.lo) / 8.0)));
    z = {std::floor(z.lo / step) * step, std::ceil(z.hi / step) * step};
  }
  CascadeLayer layer;
  layer.transform = ortho_layer(axes, x, y, z);
  layer.split_near = s.a;
  layer.split_far = s.b;
  return layer;
}

// Trapezoidal shadow map of one slice (Martin & Tan; Oliveira 2009 sec. 3.2): in the light's image
// plane the trapezoid around the slice's projection, its centre line from the near face's centre
// to the far face's, its sides through the projection centre q that puts the focus point on the
// 80% line of the map; then the homography of the trapezoid onto the unit square.
CascadeLayer fit_trapezoid(const LayoutOptions& o, const CameraFrustum& cam, const LightAxes& axes, Slice s,
                           const std::vector<WorldBox>& geometry) {
  const auto corners = cam.slice_corners(s.a, s.b);
  using P2 = std::array<double, 2>;
  const auto plane = [&](const Point3& p) { return P2{dot(p, axes.right), dot(p, axes.down)}; };
  const P2 top = plane((cam.position + (s.a * cam.forward)));
  const P2 base = plane((cam.position + (s.b * cam.forward)));
  double ex = base[0] - top[0], ey = base[1] - top[1];
  const double len = std::hypot(ex, ey);
  // Looking along the light: no direction to warp along; the uniform fit is TSM's own fall-back.
  if (!(len > 1e-3 * (s.b - s.a))) {
    LayoutOptions tight = o;
    tight.stabilize = false;
    return fit_uniform(tight, cam, axes, s, geometry);
  }
  ex /= len, ey /= len;
  const double nx = -ey, ny = ex;
  std::array<P2, 8> pts;
  Range t_range;
  for (int i = 0; i < 8; ++i) {
    pts[i] = plane(corners[i]);
    t_range.add((pts[i][0] - top[0]) * ex + (pts[i][1] - top[1]) * ey);
  }
  const double lambda = t_range.hi - t_range.lo;
  const double focus_depth = s.a * std::pow(s.b / s.a, o.tsm_focus);
  const P2 focus = plane((cam.position + (focus_depth * cam.forward)));
  double delta = (focus[0] - top[0]) * ex + (focus[1] - top[1]) * ey - t_range.lo;
  delta = std::clamp(delta, 0.01 * lambda, 0.79 * lambda);
  // y(s) = s (lambda + eta) / ((s + eta) lambda) maps the top (s = 0) to 0, the base to 1; y(delta) = 0.8.
  const double eta = 0.2 * delta * lambda / (0.8 * lambda - delta);
  const P2 q{top[0] + (t_range.lo - eta) * ex, top[1] + (t_range.lo - eta) * ey};
  double slope_lo = std::numeric_limits<double>::infinity(), slope_hi = -slope_lo;
  for (const P2& p : pts) {
    const double along = (p[0] - q[0]) * ex + (p[1] - q[1]) * ey;
    const double across = (p[0] - q[0]) * nx + (p[1] - q[1]) * ny;
    slope_lo = std::min(slope_lo, across / along);
    slope_hi = std::max(slope_hi, across / along);
  }
  const auto at = [&](double along, double slope) {
    return P2{q[0] + along * ex + along * slope * nx, q[1] + along * ey + along * slope * ny};
  };
  const std::array<P2, 4> trapezoid{at(eta, slope_lo), at(eta, slope_hi), at(eta + lambda, slope_hi),
                                    at(eta + lambda, slope_lo)};
  const std::array<P2, 4> square{P2{0, 0}, P2{1, 0}, P2{1, 1}, P2{0, 1}};
  std::array<double, 9> h = homography(trapezoid, square);
  // w > 0 inside the trapezoid (its centroid decides the sign of the whole projective map).
  const P2 mid = at(eta + 0.5 * lambda, 0.5 * (slope_lo + slope_hi));
  if (h[6] * mid[0] + h[7] * mid[1] + h[8] < 0)
    for (double& e : h) e = -e;

  Range x, y;
  for (const P2& c : trapezoid) x.add(c[0]), y.add(c[1]);
  const Range z = layer_depths(axes, x, y, corners, geometry);
  CascadeLayer layer;
  LayerTransform& t = layer.transform;
  const int rows[3] = {0, 1, 3};
  for (int r = 0; r < 3; ++r) {
    for (int i = 0; i < 3; ++i) t.m[4 * rows[r] + i] = h[3 * r] * axes.right[i] + h[3 * r + 1] * axes.down[i];
    t.m[4 * rows[r] + 3] = h[3 * r + 2];
  }
  const double zs = 1.0 / (z.hi - z.lo);
  for (int i = 0; i < 3; ++i) t.m[8 + i] = zs * axes.forward[i];
  t.m[11] = -z.lo * zs;
  layer.split_near = s.a;
  layer.split_far = s.b;
  return layer;
}

}  // namespace

LayerTransform::MapPoint LayerTransform::apply(const Point3& p) const {
  MapPoint r;
  r.w = row_at(*this, 3, p);
  r.u = row_at(*this, 0, p) / r.w;
  r.v = row_at(*this, 1, p) / r.w;
  r.d = row_at(*this, 2, p);
  return r;
}

void LayerTransform::jacobian_uv(const Point3& p, Point3& du, Point3& dv) const {
  const MapPoint q = apply(p);
  const Point3 r3 = row_xyz(*this, 3);
  du = (1.0 / q.w * (row_xyz(*this, 0) - (q.u * r3)));
  dv = (1.0 / q.w * (row_xyz(*this, 1) - (q.v * r3)));
}

bool LayerTransform::unproject(double u, double v, double d, Point3& p) const {
  const Point3 r3 = row_xyz(*this, 3);
  const std::array<Point3, 3> a{(row_xyz(*this, 0) - (u * r3)), (row_xyz(*this, 1) - (v * r3)), row_xyz(*this, 2)};
  const Point3 b{u * m[15] - m[3], v * m[15] - m[7], d - m[11]};
  return solve3(a, b, p);
}

bool LayerTransform::ray(double u, double v, Point3& origin, Point3& direction, double& depth_per_length) const {
  if (!unproject(u, v, 0.0, origin)) return false;
  Point3 far_point;
  if (!unproject(u, v, 1.0, far_point)) return false;
  const Point3 span = (far_point - origin);
  const double span_length = length(span);
  if (!(span_length > 0.0) || !std::isfinite(span_length)) return false;
  direction = (1.0 / span_length * span);
  depth_per_length = 1.0 / span_length;
  return true;
}

void validate(const CascadeSet& set) {
  if (set.layers.empty()) throw InputError("a cascade set needs at least one layer");
  if (set.layers.size() > static_cast<size_t>(kMaxCascadeLayers))
    throw InputError("a cascade set holds at most " + std::to_string(kMaxCascadeLayers) + " layers, not " +
                     std::to_string(set.layers.size()));
  if (set.width <= 0 || set.height <= 0) throw InputError("every layer of a cascade set needs a positive size");
  if (!(set.blend >= 0.0 && set.blend < 1.0)) throw InputError("the cascade blend must lie in [0, 1)");
  for (size_t k = 0; k < set.layers.size(); ++k) {
    const CascadeLayer& layer = set.layers[k];
    const std::string name = "cascade layer " + std::to_string(k);
    for (double e : layer.transform.m)
      if (!std::isfinite(e)) throw InputError(name + ": its matrix holds a non-finite entry");
    if (!std::isfinite(layer.split_near) || !std::isfinite(layer.split_far))
      throw InputError(name + ": its split depths must be finite");
    if (!(layer.split_near >= 0.0 && layer.split_far > layer.split_near))
      throw InputError(name + ": its split depths must increase (near " + std::to_string(layer.split_near) + ", far " +
                       std::to_string(layer.split_far) + ")");
    if (k > 0) {
      const double prev = set.layers[k - 1].split_far;
      if (std::abs(layer.split_near - prev) > 1e-9 * std::max(1.0, std::abs(prev)))
        throw InputError(name + ": its split starts at " + std::to_string(layer.split_near) +
                         " where the previous layer's ends at " + std::to_string(prev) +
                         " (splits must increase without gaps)");
    }
    Point3 centre;
    if (!layer.transform.unproject(0.5, 0.5, 0.5, centre) || !(layer.transform.apply(centre).w > 0.0))
      throw InputError(name + ": its world-to-map matrix is singular");
  }
}

CascadeChoice select_cascade(const CascadeSet& set, double view_depth, const Point3& p) {
  CascadeChoice choice;
  const int count = static_cast<int>(set.layers.size());
  if (!std::isfinite(view_depth) || count == 0) return choice;
  if (view_depth < set.layers.front().split_near || view_depth > set.layers.back().split_far) return choice;
  const auto on_map = [&](int k) {
    const LayerTransform::MapPoint q = set.layers[k].transform.apply(p);
    return q.w > 0.0 && q.u >= 0.0 && q.u <= 1.0 && q.v >= 0.0 && q.v <= 1.0;
  };
  int k = 0;
  while (k + 1 < count && view_depth >= set.layers[k].split_far) ++k;
  while (k < count && !on_map(k)) ++k;
  if (k == count) return choice;
  choice.layer[0] = k;
  choice.weight[0] = 1.0;
  const CascadeLayer& layer = set.layers[k];
  const double band = set.blend * (layer.split_far - layer.split_near);
  const double t = band > 0.0 ? (view_depth - (layer.split_far - band)) / band : 0.0;
  if (k + 1 < count && t > 0.0 && on_map(k + 1)) {
    const double w = std::min(t, 1.0);
    choice.layer[1] = k + 1;
    choice.weight[0] = 1.0 - w;
    choice.weight[1] = w;
  }
  return choice;
}

std::array<double, 4> layer_jacobian(const CascadeSet& set, int layer, const Point3& p, const Point3& dp_dx,
                                     const Point3& dp_dy) {
  Point3 du, dv;
  set.layers.at(layer).transform.jacobian_uv(p, du, dv);
  return {set.width * dot(du, dp_dx), set.height * dot(dv, dp_dx), set.width * dot(du, dp_dy),
          set.height * dot(dv, dp_dy)};
}

double layer_footprint(const CascadeSet& set, int layer, const Point3& p, const Point3& dp_dx, const Point3& dp_dy) {
  const std::array<double, 4> j = layer_jacobian(set, layer, p, dp_dx, dp_dy);
  return std::max(std::hypot(j[0], j[1]), std::hypot(j[2], j[3]));
}

double layer_texel_size(const CascadeSet& set, int layer, const Point3& p) {
  const LayerTransform& t = set.layers.at(layer).transform;
  // An orthonormal pair spanning the plane of constant depth.
  const Point3 n = normalize(row_xyz(t, 2));
  const Point3 ref = std::abs(n[0]) < 0.9 ? Point3{1, 0, 0} : Point3{0, 1, 0};
  const Point3 a = normalize(cross(n, ref)), b = cross(n, a);
  Point3 du, dv;
  t.jacobian_uv(p, du, dv);
  const double det = set.width * set.height * (dot(du, a) * dot(dv, b) - dot(du, b) * dot(dv, a));
  return 1.0 / std::sqrt(std::abs(det));
}

std::vector<double> practical_splits(double near_depth, double far_depth, int count, double lambda) {
  if (!(near_depth > 0.0 && far_depth > near_depth) || !std::isfinite(far_depth))
    throw InputError("cascade splits need 0 < near < far (finite)");
  if (count < 1 || count > kMaxCascadeLayers)
    throw InputError("--cascades must lie in 1.." + std::to_string(kMaxCascadeLayers));
  if (!(lambda >= 0.0 && lambda <= 1.0)) throw InputError("--split-lambda must lie in [0, 1]");
  std::vector<double> s(count + 1);
  for (int i = 0; i <= count; ++i) {
    const double f = static_cast<double>(i) / count;
    s[i] = lambda * near_depth * std::pow(far_depth / near_depth, f) +
           (1.0 - lambda) * (near_depth + (far_depth - near_depth) * f);
  }
  s.front() = near_depth;
  s.back() = far_depth;
  return s;
}

std::array<Point3, 8> CameraFrustum::slice_corners(double a, double b) const {
  const Point3 right = cross(forward, up);
  const double tan_half = std::tan(0.5 * vertical_fov_degrees * kPi / 180.0);
  std::array<Point3, 8> c;
  for (int face = 0; face < 2; ++face) {
    const double t = face == 0 ? a : b;
    const Point3 centre = (position + (t * forward));
    const double h = t * tan_half, w = h * aspect;
    for (int k = 0; k < 4; ++k) {
      const double sx = (k & 1) ? w : -w, sy = (k & 2) ? h : -h;
      c[4 * face + k] = (centre + ((sx * right) + (sy * up)));
    }
  }
  return c;
}

const char* layout_name(LayoutKind kind) {
  switch (kind) {
    case LayoutKind::Single:
      return "single";
    case LayoutKind::Pssm:
      return "pssm";
    case LayoutKind::Tsm:
      return "tsm";
    case LayoutKind::PssmTsm:
      return "pssm+tsm";
  }
  return "?";
}

LayoutKind parse_layout(const std::string& name) {
  for (LayoutKind k : {LayoutKind::Single, LayoutKind::Pssm, LayoutKind::Tsm, LayoutKind::PssmTsm})
    if (name == layout_name(k)) return k;
  throw InputError("unknown layout '" + name + "' (single, pssm, tsm, pssm+tsm)");
}

CascadeSet fit_layout(const LayoutOptions& o, const CameraFrustum& cam, const Point3& light_direction,
                      const std::vector<WorldBox>& geometry) {
  if (!(o.map_size >= 1 && o.map_size <= 65536)) throw InputError("the layer map size must lie in 1..65536");
  if (!(o.tsm_focus >= 0.0 && o.tsm_focus <= 1.0)) throw InputError("--tsm-focus must lie in [0, 1]");
  if (!(cam.vertical_fov_degrees > 0.0 && cam.vertical_fov_degrees < 170.0))
    throw InputError("--camera-fov must lie in (0, 170) degrees");
  if (!(cam.aspect > 0.0) || !std::isfinite(cam.aspect)) throw InputError("the camera's aspect must be positive");
  if (!(length(light_direction) > 0.0) || !std::isfinite(length(light_direction)))
    throw InputError("the light direction must be a finite non-zero vector");
  const bool layered = o.kind == LayoutKind::Pssm || o.kind == LayoutKind::PssmTsm;
  const int count = layered ? o.cascades : 1;
  const std::vector<double> s = practical_splits(cam.near_depth, cam.far_depth, count, o.split_lambda);
  const LightAxes axes = light_axes(light_direction);
  CascadeSet set;
  set.width = set.height = o.map_size;
  set.blend = count > 1 ? o.blend : 0.0;
  const bool warped = o.kind == LayoutKind::Tsm || o.kind == LayoutKind::PssmTsm;
  for (int k = 0; k < count; ++k) {
    // Layer k > 0 is fitted to its slice and the previous layer's blend band: select_cascade
    // mixes in the next layer only where the point lies on its map, and a tight fit (tsm, or
    // no stabilisation) that starts at the split leaves the band unblended, a visible seam.
    const double band = k > 0 ? set.blend * (s[k] - s[k - 1]) : 0.0;
    const Slice slice{s[k] - band, s[k + 1]};
    CascadeLayer layer =
        warped ? fit_trapezoid(o, cam, axes, slice, geometry) : fit_uniform(o, cam, axes, slice, geometry);
    layer.split_near = s[k];
    set.layers.push_back(layer);
  }
  validate(set);
  return set;
}

}  // namespace sf

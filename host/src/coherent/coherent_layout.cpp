#include <algorithm>
#include <cmath>
#include <string>

#include "shadowfilter/vec3.hpp"
#include "shadowfilter/coherent.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::coherent {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Hilbert curve of a side x side grid (side a power of two): the cell (x, y) of curve index d.
void hilbert_cell(int side, uint32_t d, int* x, int* y) {
  int cx = 0, cy = 0;
  uint32_t t = d;
  for (int s = 1; s < side; s *= 2) {
    const int rx = 1 & int(t / 2);
    const int ry = 1 & int(t ^ uint32_t(rx));
    if (ry == 0) {  // rotate the quadrant
      if (rx == 1) {
        cx = s - 1 - cx;
        cy = s - 1 - cy;
      }
      std::swap(cx, cy);
    }
    cx += s * rx;
    cy += s * ry;
    t /= 4;
  }
  *x = cx;
  *y = cy;
}

}  // namespace

const char* ordering_name(Ordering o) {
  switch (o) {
    case Ordering::ScanLine:
      return "scanline";
    case Ordering::ZigZag:
      return "zigzag";
    case Ordering::Hilbert:
      return "hilbert";
  }
  return "?";
}

bool parse_ordering(const std::string& s, Ordering* o) {
  for (Ordering c : {Ordering::ScanLine, Ordering::ZigZag, Ordering::Hilbert})
    if (s == ordering_name(c)) {
      *o = c;
      return true;
    }
  return false;
}

const char* far_plane_name(FarPlane f) { return f == FarPlane::Sphere ? "sphere" : "infinite"; }

bool parse_far_plane(const std::string& s, FarPlane* f) {
  for (FarPlane c : {FarPlane::Sphere, FarPlane::Infinite})
    if (s == far_plane_name(c)) {
      *f = c;
      return true;
    }
  return false;
}

void validate(const StackLayout& l) {
  if (l.views_theta < 1 || l.views_phi < 1)
    throw InputError("coherent: views_theta and views_phi must be >= 1, got " + std::to_string(l.views_theta) + "x" +
                     std::to_string(l.views_phi));
  if (long(l.views_theta) * l.views_phi > kMaxViews)
    throw InputError("coherent: at most " + std::to_string(kMaxViews) + " views (2048x2048), got " +
                     std::to_string(long(l.views_theta) * l.views_phi));
  if (l.ordering == Ordering::Hilbert && (l.views_theta != l.views_phi || !power_of_two(l.views_theta)))
    throw InputError("coherent: the hilbert ordering needs a square grid with a power-of-two side, got " +
                     std::to_string(l.views_theta) + "x" + std::to_string(l.views_phi));
  if (l.ordering != Ordering::ScanLine && l.ordering != Ordering::ZigZag && l.ordering != Ordering::Hilbert)
    throw InputError("coherent: unknown ordering " + std::to_string(uint32_t(l.ordering)));
  if (l.depth_pair != DepthPair::FirstSecond && l.depth_pair != DepthPair::FirstThird)
    throw InputError("coherent: depth_pair must be 12 or 13, got " + std::to_string(uint32_t(l.depth_pair)));
  if (l.far_plane != FarPlane::Sphere && l.far_plane != FarPlane::Infinite)
    throw InputError("coherent: unknown far_plane " + std::to_string(uint32_t(l.far_plane)));
  if (l.resolution < 1 || l.resolution > 4096)
    throw InputError("coherent: resolution must be in [1, 4096], got " + std::to_string(l.resolution));
  if (!std::isfinite(l.radius) || l.radius <= 0.0)
    throw InputError("coherent: radius must be finite and > 0, got " + std::to_string(l.radius));
  for (int axis = 0; axis < 3; ++axis)
    if (!std::isfinite(l.center[axis])) throw InputError("coherent: center must be finite");
}

std::vector<uint32_t> enumerate_views(const StackLayout& l) {
  validate(l);
  const int rows = l.views_theta, cols = l.views_phi;
  std::vector<uint32_t> seq(size_t(rows) * cols);
  for (int j = 0, i = 0; j < rows; ++j)
    for (int k = 0; k < cols; ++k, ++i) {
      switch (l.ordering) {
        case Ordering::ScanLine:
          seq[i] = uint32_t(j * cols + k);
          break;
        case Ordering::ZigZag:
          seq[i] = uint32_t(j * cols + ((j & 1) ? cols - 1 - k : k));
          break;
        case Ordering::Hilbert: {
          int x = 0, y = 0;
          hilbert_cell(cols, uint32_t(i), &x, &y);
          seq[i] = uint32_t(y * cols + x);
          break;
        }
      }
    }
  return seq;
}

std::vector<uint32_t> sequence_positions(const StackLayout& l) {
  const std::vector<uint32_t> seq = enumerate_views(l);
  std::vector<uint32_t> pos(seq.size());
  for (size_t i = 0; i < seq.size(); ++i) pos[seq[i]] = uint32_t(i);
  return pos;
}

ViewFrame view_frame(const StackLayout& l, uint32_t g) {
  const int j = int(g) / l.views_phi, k = int(g) % l.views_phi;
  const double t = (j + 0.5) * kPi / l.views_theta;
  const double p = (k + 0.5) * 2.0 * kPi / l.views_phi;
  ViewFrame f;
  f.dir = {std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p)};
  f.right = {-std::sin(p), 0.0, std::cos(p)};
  f.up = {f.dir[1] * f.right[2] - f.dir[2] * f.right[1], f.dir[2] * f.right[0] - f.dir[0] * f.right[2],
          f.dir[0] * f.right[1] - f.dir[1] * f.right[0]};
  return f;
}

uint32_t view_of_direction(const StackLayout& l, const Vec3& d) {
  const double n = std::sqrt(dot(d, d));
  const double t = std::acos(std::clamp(d[1] / n, -1.0, 1.0));
  double p = std::atan2(d[2], d[0]);
  if (p < 0.0) p += 2.0 * kPi;
  const int j = std::clamp(int(t / kPi * l.views_theta), 0, l.views_theta - 1);
  const int k = std::clamp(int(p / (2.0 * kPi) * l.views_phi), 0, l.views_phi - 1);
  return uint32_t(j * l.views_phi + k);
}

ViewPoint project(const StackLayout& l, uint32_t g, const Vec3& p) {
  const ViewFrame f = view_frame(l, g);
  const Vec3 r{p[0] - l.center[0], p[1] - l.center[1], p[2] - l.center[2]};
  const double scale = 1.0 / (2.0 * l.radius);
  const double u = dot(r, f.right) * scale + 0.5, v = dot(r, f.up) * scale + 0.5;
  const double depth = (l.radius - dot(r, f.dir)) * scale;
  ViewPoint vp;
  // Far outside the map stays outside (and fits an int).
  vp.x = int(std::floor(std::clamp(u, -1.0, 2.0) * l.resolution));
  vp.y = int(std::floor(std::clamp(v, -1.0, 2.0) * l.resolution));
  vp.q = uint32_t(std::clamp(std::nearbyint(depth * kDepthMax), 0.0, double(kDepthMax)));
  return vp;
}

Vec3 LocalLight::sample_point(uint32_t grid) const {
  if (is_mesh()) return points[grid];
  const int a = int(grid % uint32_t(samples_a)), b = int(grid / uint32_t(samples_a));
  return corner + ((a + 0.5) / samples_a) * edge_a + ((b + 0.5) / samples_b) * edge_b;
}

namespace {
bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
// The sampling grid as a layout of views (rows b, columns a): its orderings are the stacks'.
StackLayout grid_of(const LocalLight& l) {
  StackLayout g;
  g.views_theta = l.samples_b;
  g.views_phi = l.samples_a;
  g.ordering = l.ordering;
  g.resolution = 1;
  return g;
}
}  // namespace

void validate(const LocalLight& l) {
  if (l.is_mesh()) {
    if (l.points.size() > size_t(kMaxLightSamples) || l.normals.size() != l.points.size())
      throw InputError("local light: 1 to " + std::to_string(kMaxLightSamples) +
                       " sampling points on a mesh, each with its normal");
    for (size_t k = 0; k < l.points.size(); ++k)
      if (!finite3(l.points[k]) || !finite3(l.normals[k]) || !(std::fabs(length(l.normals[k]) - 1.0) < 1e-6))
        throw InputError("local light: sampling point " + std::to_string(k) + " or its normal is not finite or unit");
    if (l.samples_a != l.count() || l.samples_b != 1 || l.ordering != Ordering::ScanLine)
      throw InputError("local light: a mesh light's grid is its points in order (samples count x 1, scanline)");
    if (!std::isfinite(l.area) || l.area <= 0.0) throw InputError("local light: the mesh's area must be > 0");
    if (!std::isfinite(l.far) || l.far <= 0.0) throw InputError("local light: far must be finite and > 0");
    return;
  }
  if (!finite3(l.corner) || !finite3(l.edge_a) || !finite3(l.edge_b))
    throw InputError("local light: the corner and edges must be finite");
  if (!(dot(l.edge_a, l.edge_a) > 0.0)) throw InputError("local light: edge a must not be zero");
  if (l.samples_a < 1 || l.samples_b < 1 || long(l.samples_a) * l.samples_b > kMaxLightSamples)
    throw InputError("local light: 1 to " + std::to_string(kMaxLightSamples) + " sampling points, got " +
                     std::to_string(l.samples_a) + "x" + std::to_string(l.samples_b));
  if (l.samples_b > 1 && !(dot(l.edge_b, l.edge_b) > 0.0))
    throw InputError("local light: edge b must not be zero with more than one row of sampling points");
  if (!std::isfinite(l.far) || l.far <= 0.0) throw InputError("local light: far must be finite and > 0");
  try {
    validate(grid_of(l));
  } catch (const InputError& e) {
    throw InputError(std::string("local light's sampling grid: ") + e.what());
  }
}

StackLayout cube_layout(const LocalLight& light, int resolution, const Vec3& center, double radius) {
  validate(light);
  StackLayout l;
  l.views_theta = 6;
  l.views_phi = light.count();
  l.resolution = resolution;
  l.ordering = Ordering::ScanLine;
  l.depth_pair = DepthPair::FirstSecond;
  l.far_plane = FarPlane::Infinite;
  l.center = center;
  l.radius = radius;
  validate(l);
  return l;
}

std::vector<uint32_t> light_sequence(const LocalLight& light) {
  validate(light);
  return enumerate_views(grid_of(light));
}

std::vector<uint32_t> light_positions(const LocalLight& light) {
  validate(light);
  return sequence_positions(grid_of(light));
}

double light_far(const LocalLight& light, const Vec3& center, double radius) {
  double far = 0.0;
  for (uint32_t g = 0; g < uint32_t(light.count()); ++g) {
    const Vec3 r = light.sample_point(g) - center;
    far = std::max(far, std::sqrt(dot(r, r)) + radius);
  }
  return far;
}

CubeFace cube_face(int k) {
  const double s = (k % 2 == 0) ? 1.0 : -1.0;
  switch (k / 2) {
    case 0:
      return {{s, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    case 1:
      return {{0.0, s, 0.0}, {0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}};
    default:
      return {{0.0, 0.0, s}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  }
}

CubePoint cube_project(const LocalLight& light, int resolution, const Vec3& s, const Vec3& p) {
  const Vec3 d = p - s;
  const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  CubePoint c;
  double major;
  if (ax >= ay && ax >= az) {
    c.face = d.x >= 0.0 ? 0 : 1;
    major = ax;
  } else if (ay >= az) {
    c.face = d.y >= 0.0 ? 2 : 3;
    major = ay;
  } else {
    c.face = d.z >= 0.0 ? 4 : 5;
    major = az;
  }
  const CubeFace f = cube_face(c.face);
  // A point at the sampling point itself (major 0) reads the face's middle at depth 0.
  const double inv = major > 0.0 ? 1.0 / major : 0.0;
  const double u = dot(d, f.u) * inv, v = dot(d, f.v) * inv;
  c.x = std::clamp(int(std::floor((u + 1.0) * 0.5 * resolution)), 0, resolution - 1);
  c.y = std::clamp(int(std::floor((v + 1.0) * 0.5 * resolution)), 0, resolution - 1);
  c.q = uint32_t(std::clamp(std::nearbyint(major / light.far * kDepthMax), 0.0, double(kDepthMax)));
  return c;
}

DeviceLayout device_layout(const StackLayout& l) {
  validate(l);
  return {float(l.center[0]), float(l.center[1]), float(l.center[2]), float(l.radius),
          l.resolution,       l.views_theta,      l.views_phi,        l.views()};
}

}  // namespace sf::coherent

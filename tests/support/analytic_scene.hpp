#pragma once
// An analytic scene rendered the way renderers hand their buffers over, for the tests of
// `receivers` and of maps decoded from a light (test_inputs*.cpp): a floor, a floating sphere
// and a box on the floor; cameras and lights as OpenGL, D3D, Vulkan and reversed-Z matrices
// (row-major, p_clip = projection x view x p_world). Ray casting, rays and depths are computed
// here from the geometry alone, independently of the project's scene and receiver code.
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/view_projection.hpp"

namespace sf::test::analytic {

struct V3 {
  double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 unit(V3 a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

using M4 = std::array<double, 16>;

// A surface hit: ray parameter, unit normal (outwards), which surface (face of the box apart).
struct Hit {
  double t = std::numeric_limits<double>::infinity();
  V3 n;
  int surface = -1;  // -1: nothing; 0 floor, 1 sphere, 2..7 box faces
};

// Floor y = 0 over |x|, |z| <= 5; sphere of radius 1 at (-0.9, 1.7, 0.3); box [0.5, 2] x
// [0, 1.2] x [-1.8, -0.3] resting on the floor.
struct Scene {
  V3 sphere_centre{-0.9, 1.7, 0.3};
  double sphere_radius = 1.0;
  V3 box_lo{0.5, 0.0, -1.8}, box_hi{2.0, 1.2, -0.3};
  double floor_half = 5.0;

  Hit intersect(V3 o, V3 d, double t_min = 1e-9) const {
    Hit best;
    // floor
    if (d.y != 0.0) {
      const double t = -o.y / d.y;
      const V3 p = o + t * d;
      if (t > t_min && std::fabs(p.x) <= floor_half && std::fabs(p.z) <= floor_half && t < best.t)
        best = {t, {0, 1, 0}, 0};
    }
    // sphere
    const V3 oc = o - sphere_centre;
    const double a = dot(d, d), b = dot(oc, d), c = dot(oc, oc) - sphere_radius * sphere_radius;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      for (double t : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a})
        if (t > t_min && t < best.t) {
          best = {t, unit(o + t * d - sphere_centre), 1};
          break;
        }
    }
    // box: slabs
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    int face0 = -1, face1 = -1;
    const double os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    const double lo[3] = {box_lo.x, box_lo.y, box_lo.z}, hi[3] = {box_hi.x, box_hi.y, box_hi.z};
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      if (ds[k] == 0.0) {
        miss = os[k] < lo[k] || os[k] > hi[k];
        continue;
      }
      double ta = (lo[k] - os[k]) / ds[k], tb = (hi[k] - os[k]) / ds[k];
      int fa = 2 + 2 * k, fb = 3 + 2 * k;  // faces: 2 -x, 3 +x, 4 -y, 5 +y, 6 -z, 7 +z
      if (ta > tb) std::swap(ta, tb), std::swap(fa, fb);
      if (ta > t0) t0 = ta, face0 = fa;
      if (tb < t1) t1 = tb, face1 = fb;
    }
    if (!miss && t0 <= t1) {
      const double t = t0 > t_min ? t0 : t1;
      const int face = t0 > t_min ? face0 : face1;
      if (t > t_min && t < best.t) {
        V3 n{0, 0, 0};
        const double sign = face % 2 == 0 ? -1.0 : 1.0;
        if (face / 2 == 1) n.x = sign;
        if (face / 2 == 2) n.y = sign;
        if (face / 2 == 3) n.z = sign;
        best = {t, n, face};
      }
    }
    return best;
  }
};

inline M4 multiply(const M4& a, const M4& b) {
  M4 c{};
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k)
      for (int col = 0; col < 4; ++col) c[r * 4 + col] += a[r * 4 + k] * b[k * 4 + col];
  return c;
}

inline std::array<double, 4> transform_point(const M4& m, V3 p) {
  std::array<double, 4> r{};
  for (int i = 0; i < 4; ++i) r[i] = m[i * 4] * p.x + m[i * 4 + 1] * p.y + m[i * 4 + 2] * p.z + m[i * 4 + 3];
  return r;
}

enum class Kind { Perspective, Orthographic };
enum class Depth { Conventional, Reversed, ReversedInfinite };

// A camera or light: an OpenGL-style right-handed view (looking down -z) and a projection for
// the chosen clip space and depth mapping.
struct View {
  V3 eye, forward, right, up;  // unit axes
  Kind kind = Kind::Perspective;
  ClipSpace clip = ClipSpace::OpenGL;
  Depth depth = Depth::Conventional;
  double tan_half_x = 0, tan_half_y = 0;  // perspective
  double half_w = 0, half_h = 0;          // orthographic half extents
  double near_plane = 0, far_plane = 0;   // far: the depth of d = 1 (also for an infinite far plane)
  int width = 0, height = 0;

  M4 view_matrix() const {
    return {right.x,    right.y,    right.z,    -dot(right, eye),  up.x, up.y, up.z, -dot(up, eye),
            -forward.x, -forward.y, -forward.z, dot(forward, eye), 0,    0,    0,    1};
  }
  M4 projection_matrix() const {
    const double n = near_plane, f = far_plane;
    const double y_sign = clip == ClipSpace::Vulkan ? -1.0 : 1.0;  // Vulkan: y_ndc = -1 is the top row
    M4 p{};
    if (kind == Kind::Perspective) {
      p[0] = 1.0 / tan_half_x;
      p[5] = y_sign / tan_half_y;
      p[14] = -1.0;
      if (clip == ClipSpace::OpenGL) {
        p[10] = -(f + n) / (f - n), p[11] = -2.0 * f * n / (f - n);
      } else if (depth == Depth::Conventional) {
        p[10] = f / (n - f), p[11] = n * f / (n - f);
      } else if (depth == Depth::Reversed) {
        p[10] = n / (f - n), p[11] = n * f / (f - n);
      } else {
        p[10] = 0.0, p[11] = n;
      }
    } else {
      p[0] = 1.0 / half_w;
      p[5] = y_sign / half_h;
      p[15] = 1.0;
      if (clip == ClipSpace::OpenGL)
        p[10] = -2.0 / (f - n), p[11] = -(f + n) / (f - n);
      else
        p[10] = -1.0 / (f - n), p[11] = -n / (f - n);
    }
    return p;
  }
  ViewProjection matrices() const {
    ViewProjection vp;
    vp.view = view_matrix();
    vp.projection = projection_matrix();
    vp.clip = clip;
    if (depth != Depth::Conventional) vp.reversed_z = true;
    if (depth == Depth::ReversedInfinite) vp.infinite_far_depth = far_plane;
    return vp;
  }

  // The ray through image position (px, py) (pixels, row 0 at the top), geometrically.
  void ray(double px, double py, V3* origin, V3* dir) const {
    const double xn = 2.0 * px / width - 1.0, yn = 1.0 - 2.0 * py / height;
    if (kind == Kind::Perspective) {
      *origin = eye;
      *dir = forward + (xn * tan_half_x) * right + (yn * tan_half_y) * up;
    } else {
      *origin = eye + (xn * half_w) * right + (yn * half_h) * up;
      *dir = forward;
    }
  }
  double axis_distance(V3 p) const { return dot(p - eye, forward); }
  // The window depth of a point as the renderer's depth buffer holds it (through the matrices).
  double window_depth(V3 p) const {
    const auto c = transform_point(multiply(projection_matrix(), view_matrix()), p);
    const double ndc = c[2] / c[3];
    return clip == ClipSpace::OpenGL ? 0.5 * (ndc + 1.0) : ndc;
  }
  // Texture coordinates of a point in this view's image (u right, v down from the top row).
  void uv(V3 p, double* u, double* v) const {
    const auto c = transform_point(multiply(projection_matrix(), view_matrix()), p);
    *u = 0.5 * (c[0] / c[3] + 1.0);
    const double yn = c[1] / c[3] * (clip == ClipSpace::Vulkan ? -1.0 : 1.0);
    *v = 0.5 * (1.0 - yn);
  }
  // The filter's d of a point: its distance along the axis, normalised to the planes.
  double d(V3 p) const { return (axis_distance(p) - near_plane) / (far_plane - near_plane); }
  // Unit direction from p towards the light.
  V3 to_light(V3 p) const { return kind == Kind::Perspective ? unit(eye - p) : -1.0 * forward; }
};

inline View look_at(V3 eye, V3 target, V3 world_up, Kind kind, ClipSpace clip, Depth depth, int w, int h) {
  View v;
  v.eye = eye;
  v.forward = unit(target - eye);
  v.right = unit(cross(v.forward, world_up));
  v.up = cross(v.right, v.forward);
  v.kind = kind;
  v.clip = clip;
  v.depth = depth;
  v.width = w;
  v.height = h;
  return v;
}

// Whether p is lit by the light: nothing between p (moved off its surface along n) and the light.
inline bool lit(const Scene& s, const View& light, V3 p, V3 n) {
  const V3 l = light.to_light(p);
  if (dot(n, l) <= 0.0) return false;
  const V3 o = p + 1e-6 * n;
  const Hit h = s.intersect(o, l);
  if (light.kind == Kind::Perspective) return !(h.t < std::sqrt(dot(light.eye - o, light.eye - o)));
  return !std::isfinite(h.t);
}

// The light's depth buffer: each texel's first hit, stored as `store` says (window depth of the
// light's projection, or the distance along its axis in world units); nothing hit: the far end.
enum class Store { Window, World };
inline HostImage render_map(const Scene& s, const View& light, Store store) {
  HostImage map(light.width, light.height, 1);
  for (int j = 0; j < light.height; ++j)
    for (int i = 0; i < light.width; ++i) {
      V3 o, d;
      light.ray(i + 0.5, j + 0.5, &o, &d);
      const Hit h = s.intersect(o, d);
      const V3 p = o + h.t * d;
      const bool hit = std::isfinite(h.t) && light.axis_distance(p) < light.far_plane;
      double value;
      if (store == Store::World)
        value = hit ? light.axis_distance(p) : light.far_plane;
      else
        value = hit ? light.window_depth(p) : (light.depth == Depth::Conventional ? 1.0 : 0.0);
      map.at(i, j) = float(value);
    }
  return map;
}

// What a camera sees through each pixel centre.
struct CameraTruth {
  std::vector<float> window;      // its depth buffer (background: the far end, 1 or 0)
  std::vector<V3> point, normal;  // normal turned towards the camera
  std::vector<int> surface;       // -1 background
};
inline CameraTruth render_camera(const Scene& s, const View& cam) {
  CameraTruth t;
  const size_t n = size_t(cam.width) * cam.height;
  t.window.assign(n, cam.depth == Depth::Conventional ? 1.0f : 0.0f);
  t.point.resize(n);
  t.normal.resize(n);
  t.surface.assign(n, -1);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = size_t(y) * cam.width + x;
      V3 o, d;
      cam.ray(x + 0.5, y + 0.5, &o, &d);
      const Hit h = s.intersect(o, d);
      if (!std::isfinite(h.t)) continue;
      t.point[i] = o + h.t * d;
      t.normal[i] = dot(h.n, d) > 0.0 ? -1.0 * h.n : h.n;
      t.surface[i] = h.surface;
      t.window[i] = float(cam.window_depth(t.point[i]));
    }
  return t;
}

}  // namespace sf::test::analytic

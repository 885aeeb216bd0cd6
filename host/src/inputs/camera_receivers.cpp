// Receivers from a camera's depth buffer and a light (camera_receivers.hpp). Three passes over
// row blocks on threads: world points, then normals and footprints from the points of the
// neighbours, each pass reading only what the one before wrote.
#include "shadowfilter/camera_receivers.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "matrix4.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/normal_offset.hpp"

namespace sf {
namespace {

using detail::Mat4;
using detail::Vec4;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

Mat4 to_mat(const std::array<double, 16>& a) { return a; }

Vec3 affine_point(const Mat4& m, const Vec3& p) {
  const Vec4 r = detail::transform(m, {p.x, p.y, p.z, 1.0});
  return {r.x, r.y, r.z};
}

Vec3 affine_direction(const Mat4& m, const Vec3& d) {
  const Vec4 r = detail::transform(m, {d.x, d.y, d.z, 0.0});
  return {r.x, r.y, r.z};
}

double ndc_of_window(double w, ClipSpace clip) { return clip == ClipSpace::OpenGL ? 2.0 * w - 1.0 : w; }

// A camera: clip -> world, the two clip depths whose unprojections give each pixel's ray, where
// its eye is and which way it looks.
struct CameraModel {
  Mat4 view{}, clip_to_world{};
  ProjectionDepth depth;
  ClipSpace clip = ClipSpace::OpenGL;
  double ndc_a = 0.0, ndc_b = 0.0;  // the near plane's z_ndc and the window-depth midpoint's: both finite
  Vec3 eye{}, forward{};            // eye (perspective) and unit viewing direction, world space
  int width = 0, height = 0;
  bool affine_rays = false;  // the rays' ends as a0 + x_ndc ax + y_ndc ay (and b0, bx, by)
  Vec3 a0{}, ax{}, ay{}, b0{}, bx{}, by{};

  CameraModel(const ViewProjection& vp, int w, int h) : width(w), height(h) {
    depth = projection_depth(vp);
    clip = vp.clip;
    view = to_mat(vp.view);
    Mat4 world_to_clip = detail::multiply(to_mat(vp.projection), view);
    if (!detail::invert(world_to_clip, &clip_to_world)) throw InputError("projection x view is singular (no inverse)");
    ndc_a = ndc_of_window(depth.reversed ? 1.0 : 0.0, clip);
    ndc_b = ndc_of_window(0.5, clip);
    Mat4 view_to_world;
    detail::invert(view, &view_to_world);
    eye = affine_point(view_to_world, {0.0, 0.0, 0.0});
    forward = normalized(affine_direction(view_to_world, {0.0, 0.0, depth.forward}));
    // A projection whose depth depends on z alone (projection_depth) unprojects a plane of
    // constant z_ndc affinely: its w does not vary with x, y. The rays' ends are then affine in
    // (x_ndc, y_ndc); checked, with the general unprojection as the fallback.
    auto affine = [&](double zn, Vec3* base, Vec3* dx, Vec3* dy) {
      *base = unproject(0.0, 0.0, zn);
      *dx = unproject(1.0, 0.0, zn) - *base;
      *dy = unproject(0.0, 1.0, zn) - *base;
      const Vec3 corner = unproject(1.0, 1.0, zn), predicted = *base + *dx + *dy;
      return length(corner - predicted) <= 1e-9 * (length(corner) + length(*dx) + length(*dy));
    };
    affine_rays = affine(ndc_a, &a0, &ax, &ay) && affine(ndc_b, &b0, &bx, &by);
  }

  // Normalised device x, y of image position (px, py) in pixels (0..width, 0..height; row 0 at the top).
  double ndc_x(double px) const { return 2.0 * px / width - 1.0; }
  double ndc_y(double py) const {
    const double down = 2.0 * py / height - 1.0;
    return clip == ClipSpace::Vulkan ? down : -down;
  }

  Vec3 unproject(double xn, double yn, double zn) const {
    const Vec4 r = detail::transform(clip_to_world, {xn, yn, zn, 1.0});
    return {r.x / r.w, r.y / r.w, r.z / r.w};
  }

  // The ray through image position (px, py): origin on the near plane, direction towards the
  // window-depth midpoint (not normalised).
  void ray(double px, double py, Vec3* origin, Vec3* direction) const {
    const double xn = ndc_x(px), yn = ndc_y(py);
    if (affine_rays) {
      *origin = a0 + xn * ax + yn * ay;
      *direction = b0 + xn * bx + yn * by - *origin;
      return;
    }
    *origin = unproject(xn, yn, ndc_a);
    *direction = unproject(xn, yn, ndc_b) - *origin;
  }

  // Distance of a world point along the camera's axis.
  double axis_distance(const Vec3& p) const { return depth.forward * affine_point(view, p).z; }
};

// A light: world -> its clip space, its planes and where its light comes from.
struct LightModel {
  Mat4 view{}, world_to_clip{};
  ProjectionDepth depth;
  ClipSpace clip = ClipSpace::OpenGL;
  Vec3 position{}, to_light{};  // perspective: the light's position; orthographic: unit direction towards it

  explicit LightModel(const ViewProjection& vp) {
    depth = light_projection_depth(vp);
    clip = vp.clip;
    view = to_mat(vp.view);
    world_to_clip = detail::multiply(to_mat(vp.projection), view);
    Mat4 view_to_world;
    detail::invert(view, &view_to_world);
    position = affine_point(view_to_world, {0.0, 0.0, 0.0});
    to_light = normalized(affine_direction(view_to_world, {0.0, 0.0, -depth.forward}));
  }

  // Texture coordinates of a world point (NaN behind a perspective light).
  void uv(const Vec3& p, double* u, double* v) const {
    const Vec4 c = detail::transform(world_to_clip, {p.x, p.y, p.z, 1.0});
    if (depth.perspective && !(c.w > 0.0)) {
      *u = *v = kNaN;
      return;
    }
    const double xn = c.x / c.w, yn = c.y / c.w;
    *u = 0.5 * (xn + 1.0);
    *v = clip == ClipSpace::Vulkan ? 0.5 * (1.0 + yn) : 0.5 * (1.0 - yn);
  }

  double d(const Vec3& p) const {
    const double z = depth.forward * affine_point(view, p).z;
    return (z - depth.near_plane) / (depth.far_plane - depth.near_plane);
  }

  Vec3 direction_to_light(const Vec3& p) const { return depth.perspective ? normalized(position - p) : to_light; }
};

// Runs body(row_begin, row_end) over [0, rows) in blocks of 16 rows that the threads take in
// turn as they finish (a picture's background, which costs nothing, gathers in some rows).
template <class Body>
void for_row_blocks(int rows, int threads, const Body& body) {
  constexpr int kBlock = 16;
  const int blocks = (rows + kBlock - 1) / kBlock;
  const int n = std::max(1, std::min(threads, blocks));
  std::atomic<int> next{0};
  auto work = [&] {
    for (int b = next++; b < blocks; b = next++) body(b * kBlock, std::min(rows, (b + 1) * kBlock));
  };
  std::vector<std::thread> workers;
  workers.reserve(size_t(n - 1));
  for (int t = 1; t < n; ++t) workers.emplace_back(work);
  work();
  for (std::thread& w : workers) w.join();
}

std::string range_text(double lo, double hi) {
  std::ostringstream s;
  s << "[" << lo << ", " << hi << "]";
  return s.str();
}

void check_inputs(const CameraDepth& depth, const CameraReceiverOptions& opt, const CameraModel& camera) {
  if (depth.width <= 0 || depth.height <= 0)
    throw InputError("the camera depth image is empty (" + std::to_string(depth.width) + "x" +
                     std::to_string(depth.height) + ")");
  const size_t channels = depth.kind == CameraDepthKind::Position ? 3 : 1;
  if (depth.values.size() != size_t(depth.width) * depth.height * channels)
    throw InputError("the camera depth image holds " + std::to_string(depth.values.size()) + " values, expected " +
                     std::to_string(size_t(depth.width) * depth.height * channels));
  if (!opt.normals.empty() && opt.normals.size() != size_t(depth.width) * depth.height * 3)
    throw InputError("the normal image holds " + std::to_string(opt.normals.size()) + " values, expected " +
                     std::to_string(size_t(depth.width) * depth.height * 3) + " (3 per camera pixel)");
  if (opt.map_width <= 0 || opt.map_height <= 0)
    throw InputError(
        "CameraReceiverOptions::map_width and map_height must be positive (the shadow map's size, "
        "which footprints are measured in)");
  if (depth.kind == CameraDepthKind::Distance && !camera.depth.perspective)
    throw InputError(
        "CameraDepth::kind distance (along each pixel's ray from the eye) needs a perspective camera; "
        "an orthographic one has no eye: use view");
  if (depth.kind != CameraDepthKind::Window) return;
  // Window depth lies in [0, 1]; beyond rounding it is another kind of depth.
  double lo = INFINITY, hi = -INFINITY;
  for (float w : depth.values)
    if (std::isfinite(w)) {
      lo = std::min(lo, double(w));
      hi = std::max(hi, double(w));
    }
  const double tolerance = 2e-6;
  if (lo < -tolerance || hi > 1.0 + tolerance)
    throw InputError("the camera depth holds values in " + range_text(lo, hi) +
                     ", outside window depth's [0, 1]: distances in world units? Give CameraDepth::kind view (along "
                     "the camera's axis) or distance (along the ray)");
}

}  // namespace

const char* camera_depth_kind_name(CameraDepthKind kind) {
  switch (kind) {
    case CameraDepthKind::Window:
      return "window";
    case CameraDepthKind::View:
      return "view";
    case CameraDepthKind::Distance:
      return "distance";
    case CameraDepthKind::Position:
      return "position";
  }
  return "?";
}

Receivers camera_receivers(const ViewProjection& camera_vp, const CameraDepth& depth, const ViewProjection& light_vp,
                           const CameraReceiverOptions& opt, CameraReceiverCounts* counts) {
  const CameraModel camera(camera_vp, depth.width, depth.height);
  const LightModel light(light_vp);
  check_inputs(depth, opt, camera);
  const int W = depth.width, H = depth.height;
  const size_t n = size_t(W) * H;
  const int threads = opt.threads > 0 ? opt.threads : std::max(1u, std::thread::hardware_concurrency());

  // Pass 1: world points (NaN x on background) and the continuity measure q of each pixel: the
  // inverse axis distance for a perspective camera (affine across a plane in screen space), the
  // distance itself for an orthographic one.
  // Written whole by pass 1 on the threads, so left uninitialised here (zeroing 64 MB at 1080p
  // would cost a serial pass of its own).
  std::unique_ptr<Vec3[]> points(new Vec3[n]);
  std::unique_ptr<double[]> q(new double[n]);
  const double empty_window = camera.depth.reversed ? 0.0 : 1.0;
  const double far_limit = camera.depth.infinite_far ? INFINITY : camera.depth.far_plane;
  for_row_blocks(H, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        Vec3 p{kNaN, kNaN, kNaN};
        if (depth.kind == CameraDepthKind::Position) {
          const float* v = &depth.values[i * 3];
          if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) p = {v[0], v[1], v[2]};
        } else {
          const double s = depth.values[i];
          const double px = x + 0.5, py = y + 0.5;
          if (depth.kind == CameraDepthKind::Window) {
            if (std::isfinite(s) && s != empty_window)
              p = camera.unproject(camera.ndc_x(px), camera.ndc_y(py),
                                   ndc_of_window(std::clamp(s, 0.0, 1.0), camera.clip));
          } else if (std::isfinite(s) && s <= far_limit && (s > 0.0 || !camera.depth.perspective)) {
            Vec3 origin, dir;
            camera.ray(px, py, &origin, &dir);
            if (depth.kind == CameraDepthKind::Distance) {
              p = camera.eye + s * normalized(dir);
            } else {
              const double a = camera.axis_distance(origin), b = camera.axis_distance(origin + dir);
              p = origin + ((s - a) / (b - a)) * dir;
            }
          }
        }
        points[i] = p;
        q[i] = kNaN;
        if (std::isfinite(p.x)) {
          const double z = camera.axis_distance(p);
          q[i] = camera.depth.perspective ? 1.0 / z : z;
        }
      }
  });

  Receivers rx;
  rx.width = W;
  rx.height = H;
  rx.grid = false;
  rx.has_footprint = true;
  rx.has_ndl = true;
  rx.u.assign(n, kNaNf);
  rx.v.assign(n, kNaNf);
  rx.d.assign(n, kNaNf);
  rx.f.assign(n, kNaNf);
  rx.ndl.assign(n, kNaNf);
  rx.has_normal = true;
  rx.nx.assign(n, kNaNf);
  rx.ny.assign(n, kNaNf);
  rx.nz.assign(n, kNaNf);
  rx.has_jacobian = true;
  rx.dudx.assign(n, kNaNf);
  rx.dvdx.assign(n, kNaNf);
  rx.dudy.assign(n, kNaNf);
  rx.dvdy.assign(n, kNaNf);
  const double map_w = opt.map_width, map_h = opt.map_height;
  const double f_cap = std::max(map_w, map_h);
  const double d_tolerance = 1e-6;
  std::vector<size_t> background(size_t(H), 0), outside(size_t(H), 0), no_normal(size_t(H), 0);

  auto valid = [&](int x, int y) { return x >= 0 && y >= 0 && x < W && y < H && std::isfinite(q[size_t(y) * W + x]); };
  auto at = [&](int x, int y) { return size_t(y) * W + x; };
  // The tangent along one image axis at (x, y), step (sx, sy), as P's change per pixel. Each
  // side's neighbours extrapolate to the pixel with an error |2 q_1 - q_2 - q_0| (q affine on a
  // plane: 0 there, O(h^2) on a smooth surface, the jump's size across a discontinuity). Where the
  // two sides' errors agree (within a factor of 4) the surface runs smoothly through the pixel:
  // the central difference, O(h^2). Else the side that extrapolates better, by the one-sided
  // second-order difference (O(h^2) too), or with one neighbour on it the first-order one.
  // False without a neighbour on the surface.
  auto tangent = [&](int x, int y, int sx, int sy, Vec3* t) {
    const size_t i = at(x, y);
    const double qi = q[i];
    auto has = [&](int s) { return valid(x + s * sx, y + s * sy); };
    auto Q = [&](int s) { return q[at(x + s * sx, y + s * sy)]; };
    auto P = [&](int s) { return points[at(x + s * sx, y + s * sy)]; };
    const bool m1 = has(-1), p1 = has(+1), m2 = m1 && has(-2), p2 = p1 && has(+2);
    if (!m1 && !p1) return false;
    // A side's extrapolation error; with one neighbour only, its jump.
    auto error = [&](int s) {
      return (s > 0 ? p2 : m2) ? std::fabs(2.0 * Q(s) - Q(2 * s) - qi) : std::fabs(Q(s) - qi);
    };
    const double tiny = 1e-9 * std::fabs(qi);
    if (m1 && p1) {
      const double em = error(-1), ep = error(+1);
      const bool smooth = (m2 && p2) ? std::max(em, ep) <= 4.0 * std::min(em, ep) + tiny
                                     : std::fabs(Q(-1) + Q(1) - 2.0 * qi) <=
                                           0.25 * std::min(std::fabs(Q(-1) - qi), std::fabs(Q(1) - qi)) + tiny;
      if (smooth) {
        *t = 0.5 * (P(1) - P(-1));
        return true;
      }
    }
    const int s = !m1 ? 1 : !p1 ? -1 : (error(+1) <= error(-1) ? 1 : -1);
    const bool two = s > 0 ? p2 : m2;
    // Second order only where the far neighbour continues the near one's surface.
    if (two && std::fabs(2.0 * Q(s) - Q(2 * s) - qi) <= 0.25 * std::fabs(Q(s) - qi) + tiny)
      *t = double(s) * (0.5 * (4.0 * (P(s) - points[i]) - (P(2 * s) - points[i])));
    else
      *t = double(s) * (P(s) - points[i]);
    return true;
  };

  // Pass 2: normals, footprints, u v d ndl. Each thread keeps the rays through the horizontal
  // edges between its rows (the bottom edge of row y is the top edge of row y + 1).
  for_row_blocks(H, threads, [&](int y0, int y1) {
    const size_t row = size_t(W);
    std::vector<Vec3> top_o(row), top_d(row), bottom_o(row), bottom_d(row), side_o(row + 1), side_d(row + 1);
    for (int x = 0; x < W; ++x) camera.ray(x + 0.5, y0, &top_o[size_t(x)], &top_d[size_t(x)]);
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < W; ++x) camera.ray(x + 0.5, y + 1.0, &bottom_o[size_t(x)], &bottom_d[size_t(x)]);
      for (int x = 0; x <= W; ++x) camera.ray(x, y + 0.5, &side_o[size_t(x)], &side_d[size_t(x)]);
      for (int x = 0; x < W; ++x) {
        const size_t i = at(x, y);
        if (!std::isfinite(q[i])) {
          ++background[size_t(y)];
          continue;
        }
        const Vec3 p = points[i];
        // The camera looks at p from `view_dir` (unit, from the eye towards p).
        const Vec3 view_dir = camera.depth.perspective ? normalized(p - camera.eye) : camera.forward;
        Vec3 normal{kNaN, kNaN, kNaN};
        if (!opt.normals.empty()) {
          const float* nv = &opt.normals[i * 3];
          const Vec3 given{nv[0], nv[1], nv[2]};
          if (std::isfinite(given.x) && std::isfinite(given.y) && std::isfinite(given.z) && length(given) > 0.0)
            normal = normalized(given);
        } else {
          Vec3 tx, ty;
          if (tangent(x, y, 1, 0, &tx) && tangent(x, y, 0, 1, &ty)) {
            const Vec3 c = cross(tx, ty);
            if (length(c) > 0.0) normal = normalized(c);
          }
        }
        const bool has_normal = std::isfinite(normal.x);
        if (has_normal) {
          if (dot(normal, view_dir) > 0.0) normal = -1.0 * normal;  // towards the camera
        } else {
          ++no_normal[size_t(y)];
        }
        // The footprint's plane: the tangent plane, or without a normal the plane facing the camera.
        const Vec3 plane_n = has_normal ? normal : -1.0 * view_dir;
        const double cap = camera.depth.perspective ? length(p - camera.eye)
                                                    : std::fabs(camera.depth.far_plane - camera.depth.near_plane);
        const double cap2 = cap * cap;
        auto edge_point = [&](const Vec3& o, const Vec3& dir) {
          const double den = dot(dir, plane_n);
          const double t = den != 0.0 ? dot(p - o, plane_n) / den : kNaN;
          Vec3 hit = o + t * dir;
          Vec3 offset = hit - p;
          const double offset2 = dot(offset, offset);
          if (!(t > 0.0) || !(offset2 <= cap2)) {  // NaN fails the test too
            // The edge ray misses the plane (or meets it far away): `cap` along the plane, towards the ray.
            const double s = camera.axis_distance(p);
            const double a = camera.axis_distance(o), b = camera.axis_distance(o + dir);
            const Vec3 r = o + ((s - a) / (b - a)) * dir - p;
            const Vec3 along = r - dot(r, plane_n) * plane_n;
            offset = length(along) > 0.0 ? cap * normalized(along) : Vec3{0.0, 0.0, 0.0};
          }
          return p + offset;
        };
        // The Jacobian column from a to b in texels (its length a footprint width).
        auto texel_step = [&](const Vec3& a, const Vec3& b, double* du, double* dv) {
          double ua, va, ub, vb;
          light.uv(a, &ua, &va);
          light.uv(b, &ub, &vb);
          *du = (ub - ua) * map_w, *dv = (vb - va) * map_h;
          return std::sqrt(*du * *du + *dv * *dv);  // not hypot: its overflow care costs a sixth of the run
        };
        double jac[4];
        const double fx = texel_step(edge_point(side_o[size_t(x)], side_d[size_t(x)]),
                                     edge_point(side_o[size_t(x) + 1], side_d[size_t(x) + 1]), &jac[0], &jac[1]);
        const double fy = texel_step(edge_point(top_o[size_t(x)], top_d[size_t(x)]),
                                     edge_point(bottom_o[size_t(x)], bottom_d[size_t(x)]), &jac[2], &jac[3]);
        double f = std::max(fx, fy);
        f = std::isfinite(f) ? std::min(f, f_cap) : f_cap;
        // Columns as long as f at most (the cap); an unknown one (non-finite) leaves the receiver
        // isotropic at f (footprint.hpp).
        const bool known = std::isfinite(fx) && std::isfinite(fy);
        const double lengths[2] = {fx, fy};
        for (int c = 0; c < 4; ++c) {
          const double length = lengths[c / 2];
          jac[c] = !known ? (c == 0 || c == 3 ? f : 0.0) : length > f_cap ? jac[c] * (f_cap / length) : jac[c];
        }

        double u, v;
        light.uv(p, &u, &v);
        double d = light.d(p);
        const bool in_depth = d >= -d_tolerance && d <= 1.0 + d_tolerance;
        const bool projected = std::isfinite(u) && std::isfinite(v) && in_depth;
        if (!projected) {
          u = v = -1.0;
          d = 0.0;
        }
        if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0)) ++outside[size_t(y)];
        rx.u[i] = float(u);
        rx.v[i] = float(v);
        rx.d[i] = float(std::clamp(d, 0.0, 1.0));
        rx.f[i] = float(f);
        rx.dudx[i] = float(jac[0]);
        rx.dvdx[i] = float(jac[1]);
        rx.dudy[i] = float(jac[2]);
        rx.dvdy[i] = float(jac[3]);
        rx.ndl[i] = has_normal ? float(dot(normal, light.direction_to_light(p))) : kNaNf;
        if (has_normal && projected) {
          // The texel-scaled normal (normal_offset.hpp), over a step far below the point's texel.
          const auto map = [&](const Vec3& q) {
            double uq, vq;
            light.uv(q, &uq, &vq);
            return std::array<double, 3>{uq * map_w, vq * map_h, light.d(q)};
          };
          const std::array<float, 3> n = texel_scaled_normal(map, p, normal, 1e-4 * std::max(cap, 1e-12));
          rx.nx[i] = n[0];
          rx.ny[i] = n[1];
          rx.nz[i] = n[2];
        }
      }
      std::swap(top_o, bottom_o);
      std::swap(top_d, bottom_d);
    }
  });
  if (counts) {
    *counts = {};
    for (int y = 0; y < H; ++y) {
      counts->background += background[size_t(y)];
      counts->outside += outside[size_t(y)];
      counts->no_normal += no_normal[size_t(y)];
    }
  }
  return rx;
}

}  // namespace sf

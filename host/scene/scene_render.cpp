#include "scene_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "row_workers.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/normal_offset.hpp"

namespace sf::scene {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Shadow rays start this far (relative to the light depth range) off the surface, at most
// kShadowRayMaxOffset scene units: the offset only has to clear Embree's float error at the hit,
// which is a few ulps of the coordinates (1e-4 units at 1000), not a fraction of the scene. On the
// metre-scale scenes (city: a 1.9 km range) 1e-4 of the range put every ray origin 19 cm off its
// surface, which moved the reference's own shadow edges by more than a near cascade's texel.
constexpr double kShadowRayOffset = 1e-4;
constexpr double kShadowRayMaxOffset = 1e-2;

uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform in [0, 1) from the top 53 bits.
double uniform(uint64_t& state) { return double(splitmix64(state) >> 11) * 0x1.0p-53; }

// The soft reference's sample stream of pixel (x, y): the same in camera_view and references_at,
// so both trace one pixel with the same light samples.
uint64_t pixel_stream(unsigned seed, int x, int y) {
  uint64_t mix = (uint64_t(seed) << 40) ^ (uint64_t(y) << 20) ^ uint64_t(x);
  return splitmix64(mix);
}

}  // namespace

SceneRenderer::SceneRenderer(const SceneSetup& setup) : setup_(setup), tracer_(setup.geometry) {
  strata_ = int(std::lround(std::sqrt(double(std::max(setup.samples, 0)))));
  if (strata_ * strata_ != setup.samples || setup.samples <= 0)
    throw InputError("--samples must be a positive square number (1, 4, 16, 64, 256, ...), got " +
                     std::to_string(setup.samples));
  offset_ = std::min(kShadowRayOffset * setup.light.depth_range(), kShadowRayMaxOffset);
}

template <class RowFn>
void SceneRenderer::for_each_row(const char* label, int rows, int width, const RowFn& row_fn) const {
  scene::for_each_row(label, rows, width, setup_.threads, setup_.progress, row_fn);
}

HostImage SceneRenderer::shadow_map() const {
  HostImage image(setup_.map_width, setup_.map_height, 1);
  image.channel_names = {"Z"};
  for_each_row("shadow map", image.height, image.width, [&](int j) {
    for (int i = 0; i < image.width; ++i) {
      const Ray ray = setup_.light.texel_ray(i, j, image.width, image.height);
      const auto hit =
          tracer_.closest(ray, setup_.light.texel_ray_start(ray), std::numeric_limits<double>::infinity(), kMaskAll);
      image.at(i, j) = hit ? float(std::min(1.0, setup_.light.depth_at(ray, hit->t))) : 1.0f;
    }
  });
  return image;
}

HostImage SceneRenderer::receiver_depth() const {
  HostImage image(setup_.map_width, setup_.map_height, 1);
  image.channel_names = {"Z"};
  for_each_row("receiver depth", image.height, image.width, [&](int j) {
    for (int i = 0; i < image.width; ++i) {
      const Ray ray = setup_.light.texel_ray(i, j, image.width, image.height);
      const auto hit =
          tracer_.closest(ray, setup_.light.texel_ray_start(ray), std::numeric_limits<double>::infinity(), kMaskGround);
      image.at(i, j) = hit ? float(setup_.light.depth_at(ray, hit->t)) : kNaN;
    }
  });
  return image;
}

// The hit's normal faces the camera (surfaces are two-sided), so ndl <= 0 is the side of a
// surface the light does not reach: ortho -forward, perspective the direction to the light's
// position. The hard reference counts such a receiver as occluded (0) by the same test.
double SceneRenderer::n_dot_l(Vec3 point, Vec3 normal) const {
  double distance = 0.0;
  return dot(normal, setup_.light.towards_light(point, distance).direction);
}

bool SceneRenderer::lit_hard(Vec3 point, Vec3 normal) const {
  double distance = 0.0;
  const Ray to_light = setup_.light.towards_light(point, distance);
  if (dot(normal, to_light.direction) <= 0.0) return false;  // faces away from the light: n_dot_l <= 0
  const Ray shadow_ray{point + offset_ * normal, to_light.direction};
  return !tracer_.occluded(shadow_ray, 0.0, distance, kMaskAll);
}

// Whether the area light's point (s, t) (in [-1/2, 1/2]^2) is seen from a surface point.
bool SceneRenderer::sees_light_point(Vec3 point, Vec3 normal, double s, double t) const {
  const Vec3 origin = point + offset_ * normal;
  const Vec3 target = setup_.light.area_light_point(point, setup_.light_size, setup_.area_light_height(), s, t);
  const Vec3 delta = target - origin;
  const double distance = length(delta);
  if (!(distance > 0.0)) return false;
  const Vec3 direction = (1.0 / distance) * delta;
  if (dot(normal, direction) <= 0.0) return false;  // light sample below the surface
  return !tracer_.occluded(Ray{origin, direction}, 0.0, distance, kMaskAll);
}

double SceneRenderer::visible_fraction(Vec3 point, Vec3 normal, uint64_t stream) const {
  uint64_t state = stream;
  int visible = 0;
  for (int sy = 0; sy < strata_; ++sy) {
    for (int sx = 0; sx < strata_; ++sx) {
      const double s = (sx + uniform(state)) / strata_ - 0.5;
      const double t = (sy + uniform(state)) / strata_ - 0.5;
      visible += sees_light_point(point, normal, s, t) ? 1 : 0;
    }
  }
  return double(visible) / double(strata_ * strata_);
}

double SceneRenderer::pixel_visible_fraction(const PerspectiveCamera& camera, int x, int y, uint64_t stream) const {
  uint64_t state = stream;
  int visible = 0, hits = 0;
  for (int sy = 0; sy < strata_; ++sy) {
    for (int sx = 0; sx < strata_; ++sx) {
      const double px = x + (sx + uniform(state)) / strata_, py = y + (sy + uniform(state)) / strata_;
      const double s = (sx + uniform(state)) / strata_ - 0.5, t = (sy + uniform(state)) / strata_ - 0.5;
      const Ray ray = camera.ray_through(px, py);
      const auto hit = tracer_.closest(ray, 0.0, std::numeric_limits<double>::infinity(), kMaskAll);
      if (!hit) continue;
      ++hits;
      const Vec3 normal = dot(hit->normal, ray.direction) > 0.0 ? -1.0 * hit->normal : hit->normal;
      visible += sees_light_point(ray.at(hit->t), normal, s, t) ? 1 : 0;
    }
  }
  return hits ? double(visible) / double(hits) : 1.0;
}

// Footprint of pixel (x, y) in level-0 shadow-map texels, from the shadow-map coordinates of
// its neighbourhood: the rays through the midpoints of the pixel's left/right edges (and of
// its top/bottom edges) are intersected with the tangent plane of the hit at the pixel centre
// -- for a planar surface exactly half-way to the neighbouring pixels' own coordinates -- and
// each pair's difference in texels (du*W, dv*H) is a column of the Jacobian (footprint.hpp),
// its length a footprint width; f = the larger one. Using the tangent plane instead of the
// neighbours' hits avoids jumps at silhouettes. At grazing angles where an edge ray misses the
// plane, f is capped at the shadow-map size and that column is NaN (unknown: the lookup is then
// isotropic at f); a longer column is shortened to the cap.
SceneRenderer::Footprint SceneRenderer::footprint_texels(const PerspectiveCamera& camera, int x, int y, Vec3 point,
                                                         Vec3 normal) const {
  const double cap = std::max(setup_.map_width, setup_.map_height);
  auto coords_on_plane = [&](double px, double py) -> std::optional<LightCoords> {
    const Ray ray = camera.ray_through(px, py);
    const double denominator = dot(normal, ray.direction);
    if (std::abs(denominator) < 1e-12) return std::nullopt;
    const double t = dot(normal, point - ray.origin) / denominator;
    if (!(t > 0.0)) return std::nullopt;
    return setup_.light.project(ray.at(t));
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The column from (x0, y0) to (x1, y1) and its length (cap where a ray misses the plane).
  auto column = [&](double x0, double y0, double x1, double y1, double* du, double* dv) {
    const auto a = coords_on_plane(x0, y0);
    const auto b = coords_on_plane(x1, y1);
    if (!a || !b) {
      *du = *dv = nan;
      return cap;
    }
    *du = (b->u - a->u) * setup_.map_width;
    *dv = (b->v - a->v) * setup_.map_height;
    const double length = std::hypot(*du, *dv);
    if (length > cap) *du *= cap / length, *dv *= cap / length;
    return length;
  };
  Footprint out;
  const double across = column(x, y + 0.5, x + 1.0, y + 0.5, &out.jacobian[0], &out.jacobian[1]);
  const double down = column(x + 0.5, y, x + 0.5, y + 1.0, &out.jacobian[2], &out.jacobian[3]);
  out.f = std::min(cap, std::max(across, down));
  return out;
}

// World offsets across pixel (x, y) for the layered view: the same construction as the
// footprint (the rays through the midpoints of the pixel's left/right and top/bottom edges
// meet the hit's tangent plane; dPdx, dPdy are the differences of those points), kept in world
// units so that any layer's Jacobian turns them into its own texels. At grazing angles an offset
// is capped at the hit's distance from the camera (a layer's map spans about that much at that
// depth, as the footprint's cap is the map size), and where an edge ray misses the plane it is
// that length along the plane in the direction the edge rays spread: finite everywhere.
void SceneRenderer::pixel_offsets(const PerspectiveCamera& camera, int x, int y, Vec3 point, Vec3 normal,
                                  double distance, Vec3& dx, Vec3& dy) const {
  auto on_plane = [&](double px, double py) -> std::optional<Vec3> {
    const Ray ray = camera.ray_through(px, py);
    const double denominator = dot(normal, ray.direction);
    if (std::abs(denominator) < 1e-12) return std::nullopt;
    const double t = dot(normal, point - ray.origin) / denominator;
    if (!(t > 0.0)) return std::nullopt;
    return ray.at(t);
  };
  auto offset = [&](double x0, double y0, double x1, double y1) {
    const auto a = on_plane(x0, y0);
    const auto b = on_plane(x1, y1);
    if (a && b) {
      const Vec3 d = *b - *a;
      const double len = length(d);
      return len > distance ? (distance / len) * d : d;
    }
    const Vec3 spread = distance * (camera.ray_through(x1, y1).direction - camera.ray_through(x0, y0).direction);
    Vec3 along = spread - dot(spread, normal) * normal;
    if (!(length(along) > 0.0)) along = spread;
    return (distance / length(along)) * along;
  };
  dx = offset(x, y + 0.5, x + 1.0, y + 0.5);
  dy = offset(x + 0.5, y, x + 0.5, y + 1.0);
}

// The hit's normal in light space scaled to one texel (sf::texel_scaled_normal), over a step far
// below a texel.
std::array<float, 3> SceneRenderer::texel_scaled_normal(Vec3 point, Vec3 normal) const {
  const auto map = [this](Vec3 p) {
    const LightCoords c = setup_.light.project(p);
    return std::array<double, 3>{c.u * setup_.map_width, c.v * setup_.map_height, c.d};
  };
  return sf::texel_scaled_normal(map, point, normal, 1e-4 * std::max(setup_.light.depth_range(), 1e-12));
}

CameraImages SceneRenderer::camera_view(bool with_soft) const { return camera_view(setup_.camera, with_soft); }

CameraImages SceneRenderer::camera_view(const PerspectiveCamera& camera, bool with_soft) const {
  const int w = camera.width, h = camera.height;
  CameraImages out;
  out.receivers = HostImage(w, h, 12, kNaN);
  out.receivers.channel_names = {"u", "v", "d", "f", "ndl", "nx", "ny", "nz", "dudx", "dvdx", "dudy", "dvdy"};
  out.receivers.channel_formats = {"float", "float", "float", "half", "half", "float",
                                   "float", "float", "half",  "half", "half", "half"};
  out.reference_hard = HostImage(w, h, 1, 1.0f);
  out.reference_hard.channel_names = {"Y"};
  out.reference_hard.channel_formats = {"half"};
  if (with_soft) {
    out.reference_soft = HostImage(w, h, 1, 1.0f);
    out.reference_soft.channel_names = {"Y"};
    out.reference_soft.channel_formats = {"half"};
  }
  out.view = HostImage(w, h, 11, kNaN);
  out.view.channel_names = {"P.x",    "P.y",    "P.z",    "depth",  "dPdx.x", "dPdx.y",
                            "dPdx.z", "dPdy.x", "dPdy.y", "dPdy.z", "ndl"};
  out.view.channel_formats = std::vector<std::string>(10, "float");
  out.view.channel_formats.push_back("half");
  const Vec3 camera_axis = normalize(camera.target - camera.position);
  for_each_row(with_soft ? "camera + soft" : "camera view", h, w, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const Ray ray = camera.ray_through(x + 0.5, y + 0.5);
      const auto hit = tracer_.closest(ray, 0.0, std::numeric_limits<double>::infinity(), kMaskAll);
      if (!hit) continue;
      const Vec3 point = ray.at(hit->t);
      const LightCoords c = setup_.light.project(point);
      out.receivers.at(x, y, 0) = float(c.u);
      out.receivers.at(x, y, 1) = float(c.v);
      out.receivers.at(x, y, 2) = float(c.d);
      const Footprint footprint = footprint_texels(camera, x, y, point, hit->normal);
      out.receivers.at(x, y, 3) = float(footprint.f);
      for (int c = 0; c < 4; ++c) out.receivers.at(x, y, 8 + c) = float(footprint.jacobian[size_t(c)]);
      const double ndl = n_dot_l(point, hit->normal);
      out.receivers.at(x, y, 4) = float(ndl);
      const std::array<float, 3> n = texel_scaled_normal(point, hit->normal);
      for (int c = 0; c < 3; ++c) out.receivers.at(x, y, 5 + c) = n[size_t(c)];
      Vec3 dx, dy;
      pixel_offsets(camera, x, y, point, hit->normal, hit->t, dx, dy);
      const double view_values[11] = {point.x, point.y, point.z, dot(point - camera.position, camera_axis),
                                      dx.x,    dx.y,    dx.z,    dy.x,
                                      dy.y,    dy.z,    ndl};
      for (int c = 0; c < 11; ++c) out.view.at(x, y, c) = float(view_values[c]);
      out.reference_hard.at(x, y) = lit_hard(point, hit->normal) ? 1.0f : 0.0f;
      if (with_soft) {
        const uint64_t stream = pixel_stream(setup_.seed, x, y);
        out.reference_soft.at(x, y) = float(setup_.pixel_average ? pixel_visible_fraction(camera, x, y, stream)
                                                                 : visible_fraction(point, hit->normal, stream));
      }
    }
  });
  return out;
}

CameraImages SceneRenderer::references_at(const ViewReceivers& view, Vec3 camera_position, bool with_soft) const {
  const int w = view.width, h = view.height;
  CameraImages out;
  out.reference_hard = HostImage(w, h, 1, 1.0f);
  out.reference_hard.channel_names = {"Y"};
  if (with_soft) {
    out.reference_soft = HostImage(w, h, 1, 1.0f);
    out.reference_soft.channel_names = {"Y"};
  }
  for_each_row("references at points", h, w, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!std::isfinite(view.x[i]) || !std::isfinite(view.depth[i])) continue;
      const Vec3 point{view.x[i], view.y[i], view.z[i]};
      Vec3 normal = cross(Vec3{view.dxx[i], view.dxy[i], view.dxz[i]}, Vec3{view.dyx[i], view.dyy[i], view.dyz[i]});
      const double n = length(normal);
      if (!(n > 0.0)) continue;
      normal = (1.0 / n) * normal;
      if (dot(normal, camera_position - point) < 0.0) normal = -1.0 * normal;
      out.reference_hard.at(x, y) = lit_hard(point, normal) ? 1.0f : 0.0f;
      if (with_soft) {
        out.reference_soft.at(x, y) = float(visible_fraction(point, normal, pixel_stream(setup_.seed, x, y)));
      }
    }
  });
  return out;
}

double min_occluder_floor_gap(const HostImage& shadow_map, const HostImage& receiver_depth) {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < shadow_map.data.size(); ++k) {
    const float floor_depth = receiver_depth.data[k];
    const float first_depth = shadow_map.data[k];
    // Self-shadowing ground (terrain) sits within a hair of its own depth: only count gaps
    // larger than float noise.
    if (std::isfinite(floor_depth) && first_depth < floor_depth - 1e-6f)
      gap = std::min(gap, double(floor_depth) - first_depth);
  }
  return gap;
}

}  // namespace sf::scene

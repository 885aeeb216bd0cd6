#include "scene_views.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;

Interval widened(Interval range, double margin) {
  const double pad = margin * (range.hi - range.lo);
  return {range.lo - pad, range.hi + pad};
}

// Same length for both intervals (the longer one's), each keeping its centre.
void make_equal_length(Interval& a, Interval& b) {
  const double half = 0.5 * std::max(a.hi - a.lo, b.hi - b.lo);
  const double centre_a = 0.5 * (a.lo + a.hi);
  const double centre_b = 0.5 * (b.lo + b.hi);
  a = {centre_a - half, centre_a + half};
  b = {centre_b - half, centre_b + half};
}

// "Down" in the shadow map is world +z projected onto the light's image plane (world +x when
// the light looks along z).
void make_basis(LightView& light, Vec3 direction) {
  light.forward = normalize(direction);
  Vec3 ref{0.0, 0.0, 1.0};
  if (std::abs(dot(ref, light.forward)) > 0.99) ref = {1.0, 0.0, 0.0};
  light.down = normalize(ref - dot(ref, light.forward) * light.forward);
  light.right = cross(light.down, light.forward);
}

}  // namespace

LightView LightView::fit_ortho(const SceneGeometry& scene, Vec3 direction, double margin) {
  if (!(length(direction) > 0.0)) throw InputError("--light-dir must not be the zero vector");
  LightView light;
  light.type = LightType::Ortho;
  make_basis(light, direction);
  light.right_range = widened(project_onto(scene, light.right), margin);
  light.down_range = widened(project_onto(scene, light.down), margin);
  make_equal_length(light.right_range, light.down_range);
  const Interval depth = widened(project_onto(scene, light.forward), margin);
  light.near_plane = depth.lo;
  light.far_plane = depth.hi;
  return light;
}

LightView LightView::fit_perspective(const SceneGeometry& scene, Vec3 position, Vec3 target, double fov_degrees,
                                     double margin) {
  if (!(length(target - position) > 0.0)) throw InputError("--light-pos must differ from the scene centre it looks at");
  LightView light;
  light.type = LightType::Perspective;
  light.position = position;
  make_basis(light, target - position);
  double z_min = std::numeric_limits<double>::infinity(), z_max = 0.0, slope = 0.0;
  for (const Vec3& p : hull_points(scene)) {
    const Vec3 q = p - position;
    const double z = dot(q, light.forward);
    if (!(z > 0.0))
      throw InputError(
          "the perspective light at --light-pos must see the whole scene in front "
          "of it (geometry lies behind the light)");
    z_min = std::min(z_min, z);
    z_max = std::max(z_max, z);
    slope = std::max({slope, std::abs(dot(q, light.right)) / z, std::abs(dot(q, light.down)) / z});
  }
  const double pad = margin * (z_max - z_min);
  light.near_plane = std::max(z_min - pad, 1e-3 * z_max);
  light.far_plane = z_max + pad;
  if (fov_degrees > 0.0) {
    light.fov_degrees = fov_degrees;
  } else {
    light.fov_degrees = 2.0 * std::atan(slope * (1.0 + 2.0 * margin)) * 180.0 / kPi;
    if (!(light.fov_degrees < 170.0))
      throw InputError(
          "the scene needs a field of view over 170 degrees from --light-pos; move "
          "the light away from the scene");
  }
  return light;
}

double LightView::tan_half_fov() const { return std::tan(0.5 * fov_degrees * kPi / 180.0); }

Ray LightView::texel_ray(int i, int j, int width, int height) const {
  const double u = (i + 0.5) / width;
  const double v = (j + 0.5) / height;
  if (type == LightType::Ortho) {
    const double a = right_range.lo + u * (right_range.hi - right_range.lo);
    const double b = down_range.lo + v * (down_range.hi - down_range.lo);
    return Ray{a * right + b * down + near_plane * forward, forward};
  }
  const double th = tan_half_fov();
  return Ray{position, normalize(forward + ((2.0 * u - 1.0) * th) * right + ((2.0 * v - 1.0) * th) * down)};
}

double LightView::texel_ray_start(const Ray& ray) const {
  if (type == LightType::Ortho) return 0.0;
  return near_plane / dot(ray.direction, forward);
}

double LightView::depth_at(const Ray& ray, double t) const {
  if (type == LightType::Ortho) return t / depth_range();
  return (t * dot(ray.direction, forward) - near_plane) / depth_range();
}

LightCoords LightView::project(Vec3 p) const {
  if (type == LightType::Ortho) {
    return {(dot(p, right) - right_range.lo) / (right_range.hi - right_range.lo),
            (dot(p, down) - down_range.lo) / (down_range.hi - down_range.lo),
            (dot(p, forward) - near_plane) / depth_range()};
  }
  const Vec3 q = p - position;
  const double z = dot(q, forward);
  const double th = tan_half_fov();
  return {0.5 + 0.5 * dot(q, right) / (z * th), 0.5 + 0.5 * dot(q, down) / (z * th), (z - near_plane) / depth_range()};
}

Ray LightView::towards_light(Vec3 p, double& distance) const {
  if (type == LightType::Ortho) {
    distance = std::max(0.0, dot(p, forward) - near_plane);
    return Ray{p, -forward};
  }
  distance = length(position - p);
  return Ray{p, normalize(position - p)};
}

Vec3 LightView::area_light_point(Vec3 p, double width, double height, double s, double t) const {
  const Vec3 offset = (width * s) * right + (height * t) * down;
  if (type == LightType::Ortho) return p - (dot(p, forward) - near_plane) * forward + offset;
  return position + offset;
}

Ray PerspectiveCamera::ray_through(double x, double y) const {
  const Vec3 forward = normalize(target - position);
  const Vec3 right = normalize(cross(forward, up_hint));
  const Vec3 up = cross(right, forward);
  const double half_height = std::tan(0.5 * vertical_fov_degrees * kPi / 180.0);
  const double half_width = half_height * width / height;
  const double sx = (2.0 * x / width - 1.0) * half_width;
  const double sy = (1.0 - 2.0 * y / height) * half_height;
  return Ray{position, normalize(forward + sx * right + sy * up)};
}

}  // namespace sf::scene

#include "scene_views.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace

OrthoLight OrthoLight::fit(const SceneGeometry& scene, Vec3 direction, double margin) {
  OrthoLight light;
  light.forward = normalize(direction);
  // "Down" in the shadow map is world +z projected onto the light's image plane.
  const Vec3 world_z{0.0, 0.0, 1.0};
  light.down = normalize(world_z - dot(world_z, light.forward) * light.forward);
  light.right = cross(light.down, light.forward);
  light.right_range = widened(project_onto(scene, light.right), margin);
  light.down_range = widened(project_onto(scene, light.down), margin);
  make_equal_length(light.right_range, light.down_range);
  const Interval depth = widened(project_onto(scene, light.forward), margin);
  light.near_plane = depth.lo;
  light.far_plane = depth.hi;
  return light;
}

Ray OrthoLight::texel_ray(int i, int j, int width, int height) const {
  const double u = (i + 0.5) / width;
  const double v = (j + 0.5) / height;
  const double a = right_range.lo + u * (right_range.hi - right_range.lo);
  const double b = down_range.lo + v * (down_range.hi - down_range.lo);
  return Ray{a * right + b * down + near_plane * forward, forward};
}

LightCoords OrthoLight::project(Vec3 p) const {
  return {(dot(p, right) - right_range.lo) / (right_range.hi - right_range.lo),
          (dot(p, down) - down_range.lo) / (down_range.hi - down_range.lo),
          (dot(p, forward) - near_plane) / depth_range()};
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

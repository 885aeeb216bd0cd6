#include "scene_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sf::scene {
namespace {

constexpr double kParallelEpsilon = 1e-12;

Vec3 axis_vector(int axis, double sign) {
  Vec3 v;
  if (axis == 0) v.x = sign;
  if (axis == 1) v.y = sign;
  if (axis == 2) v.z = sign;
  return v;
}

std::optional<Hit> intersect_floor(const Ray& ray, const FloorSquare& floor, double t_min) {
  if (std::abs(ray.direction.y) < kParallelEpsilon) return std::nullopt;
  const double t = -ray.origin.y / ray.direction.y;
  if (!(t > t_min)) return std::nullopt;
  const Vec3 p = ray.at(t);
  if (std::abs(p.x) > floor.half_size || std::abs(p.z) > floor.half_size) return std::nullopt;
  // Two-sided: the normal faces the incoming ray.
  const Vec3 normal{0.0, ray.direction.y < 0.0 ? 1.0 : -1.0, 0.0};
  return Hit{t, normal, SceneObject::Floor};
}

std::optional<Hit> intersect_sphere(const Ray& ray, const Sphere& sphere, double t_min) {
  const Vec3 offset = ray.origin - sphere.center;
  const double half_b = dot(offset, ray.direction);
  const double c = dot(offset, offset) - sphere.radius * sphere.radius;
  const double discriminant = half_b * half_b - c;
  if (discriminant < 0.0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  double t = -half_b - root;
  if (!(t > t_min)) t = -half_b + root;
  if (!(t > t_min)) return std::nullopt;
  const Vec3 normal = (1.0 / sphere.radius) * (ray.at(t) - sphere.center);
  return Hit{t, normal, SceneObject::Sphere};
}

// Slab test. A ray starting inside the box reports the exit face.
std::optional<Hit> intersect_box(const Ray& ray, const Box& box, double t_min) {
  double t_enter = -std::numeric_limits<double>::infinity();
  double t_exit = std::numeric_limits<double>::infinity();
  Vec3 enter_normal;
  Vec3 exit_normal;
  for (int axis = 0; axis < 3; ++axis) {
    const double origin = component(ray.origin, axis);
    const double direction = component(ray.direction, axis);
    const double lo = component(box.min_corner, axis);
    const double hi = component(box.max_corner, axis);
    if (std::abs(direction) < kParallelEpsilon) {
      if (origin < lo || origin > hi) return std::nullopt;
      continue;
    }
    // Entering through the face the ray travels towards first.
    const double sign = direction > 0.0 ? 1.0 : -1.0;
    const double t_near = ((direction > 0.0 ? lo : hi) - origin) / direction;
    const double t_far = ((direction > 0.0 ? hi : lo) - origin) / direction;
    if (t_near > t_enter) {
      t_enter = t_near;
      enter_normal = axis_vector(axis, -sign);
    }
    if (t_far < t_exit) {
      t_exit = t_far;
      exit_normal = axis_vector(axis, sign);
    }
  }
  if (t_enter > t_exit) return std::nullopt;
  if (t_enter > t_min) return Hit{t_enter, enter_normal, SceneObject::Box};
  if (t_exit > t_min) return Hit{t_exit, exit_normal, SceneObject::Box};
  return std::nullopt;
}

void keep_nearest(std::optional<Hit>& nearest, const std::optional<Hit>& candidate) {
  if (candidate && (!nearest || candidate->t < nearest->t)) nearest = candidate;
}

std::array<Vec3, 8> box_corners(const Box& box) {
  std::array<Vec3, 8> corners;
  for (int k = 0; k < 8; ++k) {
    corners[k] = {(k & 1) ? box.max_corner.x : box.min_corner.x,
                  (k & 2) ? box.max_corner.y : box.min_corner.y,
                  (k & 4) ? box.max_corner.z : box.min_corner.z};
  }
  return corners;
}

void extend(Interval& range, double value) {
  range.lo = std::min(range.lo, value);
  range.hi = std::max(range.hi, value);
}

}  // namespace

std::optional<Hit> closest_hit(const Ray& ray, const SceneGeometry& scene, SurfaceSet surfaces,
                               double t_min) {
  std::optional<Hit> nearest = intersect_floor(ray, scene.floor, t_min);
  if (surfaces == SurfaceSet::All) {
    keep_nearest(nearest, intersect_sphere(ray, scene.sphere, t_min));
    keep_nearest(nearest, intersect_box(ray, scene.box, t_min));
  }
  return nearest;
}

bool any_hit(const Ray& ray, const SceneGeometry& scene, double t_min) {
  return intersect_sphere(ray, scene.sphere, t_min) || intersect_box(ray, scene.box, t_min) ||
         intersect_floor(ray, scene.floor, t_min);
}

Interval project_onto(const SceneGeometry& scene, Vec3 axis) {
  const double sphere_center = dot(scene.sphere.center, axis);
  Interval range{sphere_center - scene.sphere.radius, sphere_center + scene.sphere.radius};
  for (const Vec3& corner : box_corners(scene.box)) extend(range, dot(corner, axis));
  const double h = scene.floor.half_size;
  for (double x : {-h, h}) {
    for (double z : {-h, h}) extend(range, dot(Vec3{x, 0.0, z}, axis));
  }
  return range;
}

SceneGeometry make_spheres_scene() {
  SceneGeometry scene;
  scene.name = "spheres";
  scene.floor.half_size = 4.0;
  // Both occluders float above the floor so that every occluder-floor pair is at least
  // 0.15 apart in normalised light depth (ESM with c = 80 is then < 1e-3 in the umbra).
  scene.sphere = Sphere{Vec3{-1.3, 2.2, 0.9}, 0.9};
  scene.box = Box{Vec3{0.4, 1.2, -2.2}, Vec3{2.2, 2.0, -0.6}};
  return scene;
}

}  // namespace sf::scene

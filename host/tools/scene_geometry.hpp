#pragma once
// Analytic scene geometry of the bundled scenes: a finite floor square, a sphere and an
// axis-aligned box, with closest-hit and any-hit ray queries (no external ray tracer).
#include <optional>
#include <string>

#include "scene_math.hpp"

namespace sf::scene {

// Finite floor: the square |x| <= half_size, |z| <= half_size of the plane y = 0, normal +y.
struct FloorSquare {
  double half_size = 1.0;
};

struct Sphere {
  Vec3 center;
  double radius = 1.0;
};

struct Box {
  Vec3 min_corner;
  Vec3 max_corner;
};

struct SceneGeometry {
  std::string name;
  FloorSquare floor;
  Sphere sphere;  // occluder
  Box box;        // occluder
};

enum class SceneObject { Floor, Sphere, Box };

struct Hit {
  double t = 0.0;
  Vec3 normal;  // unit, pointing out of the surface that was hit
  SceneObject object = SceneObject::Floor;
};

// Which surfaces a query sees.
enum class SurfaceSet { All, FloorOnly };

// Nearest intersection with t > t_min among the chosen surfaces.
std::optional<Hit> closest_hit(const Ray& ray, const SceneGeometry& scene, SurfaceSet surfaces,
                               double t_min = 0.0);

// True when anything in the scene is hit with t > t_min (shadow rays).
bool any_hit(const Ray& ray, const SceneGeometry& scene, double t_min = 0.0);

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};

// Exact range of dot(p, axis) over every point p of the scene's geometry (axis: unit vector).
Interval project_onto(const SceneGeometry& scene, Vec3 axis);

// The bundled "spheres" scene: floor, a floating sphere and a floating box.
SceneGeometry make_spheres_scene();

}  // namespace sf::scene

#pragma once
// Scene geometry: triangle meshes and analytic spheres, each either part of the ground (the
// planar receivers: floor or terrain) or an occluder. Ray casting is in ray_tracer.hpp (Embree).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene_math.hpp"

namespace sf::scene {

struct TriMesh {
  std::string name;
  bool ground = false;  // part of the receiver surface of --receiver-depth (floor, terrain)
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
};

struct Sphere {
  std::string name;
  Vec3 center;
  double radius = 1.0;
};

struct SceneGeometry {
  std::string name;
  std::vector<TriMesh> meshes;
  std::vector<Sphere> spheres;  // occluders, intersected analytically by Embree
  // One JSON value per object ({"type": ..., parameters}) for scene.json.
  std::vector<std::string> description;

  bool has_ground() const;
  size_t triangle_count() const;
  size_t vertex_count() const;
};

// Exact range of dot(p, axis) over every point p of the geometry (axis: unit vector).
Interval project_onto(const SceneGeometry& scene, Vec3 axis);
// Points whose convex hull contains the geometry (vertices, sphere bounding-box corners).
std::vector<Vec3> hull_points(const SceneGeometry& scene);

// Builders. All boxes, quads and prisms are closed or two-sided triangle meshes.
void add_floor(SceneGeometry& scene, double half_size);  // y = 0, |x|,|z| <= half_size, ground
void add_box(SceneGeometry& scene, const std::string& name, Vec3 min_corner, Vec3 max_corner);
// The same closed box appended to an existing mesh (many boxes in one mesh: a city's buildings).
void append_box(TriMesh& mesh, Vec3 min_corner, Vec3 max_corner);
// Parallelogram corner + s*edge_a + t*edge_b, s,t in [0,1] (zero thickness, two-sided).
void add_quad(SceneGeometry& scene, const std::string& name, Vec3 corner, Vec3 edge_a, Vec3 edge_b,
              bool ground = false);
// Closed n-sided prism (a cylinder approximation) from a to b with radii ra at a, rb at b.
void add_prism(TriMesh& mesh, Vec3 a, Vec3 b, double ra, double rb, int sides);
void add_sphere(SceneGeometry& scene, const std::string& name, Vec3 center, double radius);

}  // namespace sf::scene

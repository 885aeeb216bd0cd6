#include "scene_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene_files.hpp"

namespace sf::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;

void extend(Interval& range, double value) {
  range.lo = std::min(range.lo, value);
  range.hi = std::max(range.hi, value);
}

uint32_t push(TriMesh& mesh, Vec3 v) {
  mesh.vertices.push_back(v);
  return static_cast<uint32_t>(mesh.vertices.size() - 1);
}

}  // namespace

bool SceneGeometry::has_ground() const {
  return std::any_of(meshes.begin(), meshes.end(), [](const TriMesh& m) { return m.ground; });
}

size_t SceneGeometry::triangle_count() const {
  size_t n = 0;
  for (const TriMesh& m : meshes) n += m.triangles.size();
  return n;
}

size_t SceneGeometry::vertex_count() const {
  size_t n = 0;
  for (const TriMesh& m : meshes) n += m.vertices.size();
  return n;
}

Interval project_onto(const SceneGeometry& scene, Vec3 axis) {
  Interval range{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const TriMesh& mesh : scene.meshes)
    for (const Vec3& v : mesh.vertices) extend(range, dot(v, axis));
  for (const Sphere& s : scene.spheres) {
    extend(range, dot(s.center, axis) - s.radius);
    extend(range, dot(s.center, axis) + s.radius);
  }
  return range;
}

std::vector<Vec3> hull_points(const SceneGeometry& scene) {
  std::vector<Vec3> points;
  for (const TriMesh& mesh : scene.meshes) points.insert(points.end(), mesh.vertices.begin(), mesh.vertices.end());
  for (const Sphere& s : scene.spheres)
    for (int k = 0; k < 8; ++k)
      points.push_back(s.center + Vec3{(k & 1) ? s.radius : -s.radius, (k & 2) ? s.radius : -s.radius,
                                       (k & 4) ? s.radius : -s.radius});
  return points;
}

void add_floor(SceneGeometry& scene, double half_size) {
  add_quad(scene, "floor", {-half_size, 0.0, -half_size}, {2 * half_size, 0.0, 0.0}, {0.0, 0.0, 2 * half_size},
           /*ground=*/true);
  scene.description.back() =
      "{\"type\": \"floor\", \"plane\": \"y = 0\", \"half_size\": " + format_number(half_size) + "}";
}

void add_quad(SceneGeometry& scene, const std::string& name, Vec3 corner, Vec3 edge_a, Vec3 edge_b, bool ground) {
  TriMesh mesh;
  mesh.name = name;
  mesh.ground = ground;
  mesh.vertices = {corner, corner + edge_a, corner + edge_a + edge_b, corner + edge_b};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  scene.meshes.push_back(std::move(mesh));
  scene.description.push_back("{\"type\": \"quad\", \"name\": " + json_string(name) +
                              ", \"corner\": " + json_vector(corner) + ", \"edge_a\": " + json_vector(edge_a) +
                              ", \"edge_b\": " + json_vector(edge_b) + "}");
}

void append_box(TriMesh& mesh, Vec3 lo, Vec3 hi) {
  const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  for (int k = 0; k < 8; ++k)
    mesh.vertices.push_back({(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z});
  // Faces as quads of corner indices (outward winding).
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    mesh.triangles.push_back({base + f[0], base + f[2], base + f[3]});
  }
}

void add_box(SceneGeometry& scene, const std::string& name, Vec3 lo, Vec3 hi) {
  TriMesh mesh;
  mesh.name = name;
  append_box(mesh, lo, hi);
  scene.meshes.push_back(std::move(mesh));
  scene.description.push_back("{\"type\": \"box\", \"name\": " + json_string(name) + ", \"min\": " + json_vector(lo) +
                              ", \"max\": " + json_vector(hi) + "}");
}

void add_prism(TriMesh& mesh, Vec3 a, Vec3 b, double ra, double rb, int sides) {
  const Vec3 axis = normalize(b - a);
  const Vec3 helper = std::abs(axis.y) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  const Vec3 e1 = normalize(cross(axis, helper));
  const Vec3 e2 = cross(axis, e1);
  const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  for (int k = 0; k < sides; ++k) {
    const double phi = 2.0 * kPi * k / sides;
    const Vec3 dir = std::cos(phi) * e1 + std::sin(phi) * e2;
    push(mesh, a + ra * dir);
    push(mesh, b + rb * dir);
  }
  const uint32_t ca = push(mesh, a);
  const uint32_t cb = push(mesh, b);
  for (int k = 0; k < sides; ++k) {
    const uint32_t a0 = base + 2 * k, b0 = a0 + 1;
    const uint32_t a1 = base + 2 * ((k + 1) % sides), b1 = a1 + 1;
    mesh.triangles.push_back({a0, a1, b1});
    mesh.triangles.push_back({a0, b1, b0});
    mesh.triangles.push_back({ca, a1, a0});
    mesh.triangles.push_back({cb, b0, b1});
  }
}

void add_sphere(SceneGeometry& scene, const std::string& name, Vec3 center, double radius) {
  scene.spheres.push_back({name, center, radius});
  scene.description.push_back("{\"type\": \"sphere\", \"name\": " + json_string(name) +
                              ", \"center\": " + json_vector(center) + ", \"radius\": " + format_number(radius) + "}");
}

}  // namespace sf::scene

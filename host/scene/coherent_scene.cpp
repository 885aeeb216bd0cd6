#include "coherent_scene.hpp"

#include <algorithm>
#include <cmath>

namespace sf::scene {

RigidTransform SceneObject::at_frame(int frame) const {
  RigidTransform t = placement;
  if (frame > 0 && spin_degrees != 0.0)
    t = t.then(rotation_about(spin_axis, spin_degrees * frame, t.apply(center()), "--spin"));
  if (frame > 0) t = t.then(translation_by(double(frame) * move));
  return t;
}

Vec3 SceneObject::center() const {
  const auto& c = stack->layout.center;
  return {c[0], c[1], c[2]};
}

SceneGeometry world_geometry(const std::vector<SceneObject>& objects, const std::vector<GroundPlane>& planes, int frame,
                             std::vector<std::array<float, 3>>* albedo_of_geometry) {
  SceneGeometry world;
  world.name = "coherent scene";
  std::vector<std::array<float, 3>> mesh_albedo, sphere_albedo;
  for (size_t k = 0; k < objects.size(); ++k) {
    const SceneObject& o = objects[k];
    const RigidTransform t = o.at_frame(frame);
    for (TriMesh m : o.geometry.meshes) {
      for (Vec3& v : m.vertices) v = t.apply(v);
      m.ground = false;
      m.name = "object" + std::to_string(k + 1) + "/" + m.name;
      world.meshes.push_back(std::move(m));
      mesh_albedo.push_back(o.albedo);
    }
    for (Sphere s : o.geometry.spheres) {
      s.center = t.apply(s.center);
      world.spheres.push_back(s);
      sphere_albedo.push_back(o.albedo);
    }
  }
  for (size_t k = 0; k < planes.size(); ++k) {
    const GroundPlane& p = planes[k];
    const double h = p.half_size;
    add_quad(world, "ground" + std::to_string(k + 1), {p.cx - h, p.height, p.cz - h}, {2.0 * h, 0.0, 0.0},
             {0.0, 0.0, 2.0 * h}, true);
    mesh_albedo.push_back(p.albedo);
  }
  if (albedo_of_geometry) {
    *albedo_of_geometry = mesh_albedo;
    albedo_of_geometry->insert(albedo_of_geometry->end(), sphere_albedo.begin(), sphere_albedo.end());
  }
  return world;
}

std::vector<PlacedStack> placed_stacks(const std::vector<SceneObject>& objects, int frame) {
  std::vector<PlacedStack> out;
  for (const SceneObject& o : objects) out.push_back({o.stack, o.at_frame(frame)});
  return out;
}

void scene_bounds(const std::vector<SceneObject>& objects, int frame, Vec3* center, double* radius) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const SceneObject& o : objects) {
    const Vec3 c = o.at_frame(frame).apply(o.center());
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a] - o.radius());
      hi[a] = std::max(hi[a], c[a] + o.radius());
    }
  }
  *center = 0.5 * (lo + hi);
  double r = 0.0;
  for (const SceneObject& o : objects)
    r = std::max(r, length(o.at_frame(frame).apply(o.center()) - *center) + o.radius());
  *radius = r;
}

}  // namespace sf::scene

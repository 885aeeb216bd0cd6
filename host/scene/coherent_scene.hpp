#pragma once
// Several objects with coherent shadow maps in one render (Ritschel 2007 sec. 4.6;
// docs/coherent_render.md): each object its own maps and a rigid placement that may change from
// frame to frame (a translation and a spin per frame), receiver-only ground planes that take the
// objects' shadows and cast none, and the world geometry the G-buffer and the Embree reference
// trace for a frame.
#include <array>
#include <string>
#include <vector>

#include "shadowfilter/coherent.hpp"

#include "coherent_render.hpp"
#include "scene_geometry.hpp"

namespace sf::scene {

struct SceneObject {
  const coherent::CompressedStack* stack = nullptr;  // the caller's
  SceneGeometry geometry;                            // in the object's frame, as its maps were built
  RigidTransform placement;                          // at frame 0
  Vec3 move{0.0, 0.0, 0.0};                          // translation per frame
  Vec3 spin_axis{0.0, 1.0, 0.0};                     // rotation per frame about the object's centre
  double spin_degrees = 0.0;
  std::array<float, 3> albedo{0.8f, 0.8f, 0.8f};

  // placement, then f spins about the placed centre, then f moves.
  RigidTransform at_frame(int frame) const;
  // The maps' bounding sphere centre, in the object's frame.
  Vec3 center() const;
  double radius() const { return stack->layout.radius; }
};

// A receiver-only square y = height, |x - cx|, |z - cz| <= half_size: in the G-buffer, never an
// occluder (it has no maps, and the Embree reference skips it too).
struct GroundPlane {
  double height = 0.0, half_size = 1.0, cx = 0.0, cz = 0.0;
  std::array<float, 3> albedo{0.8f, 0.8f, 0.8f};
};

// The world of frame f: every object's geometry placed (all of it an occluder, ground flags
// dropped: the maps hold all of it), then the planes (ground). albedo_of_geometry receives the
// albedo of each geometry in RayTracer's order (meshes, then spheres).
SceneGeometry world_geometry(const std::vector<SceneObject>& objects, const std::vector<GroundPlane>& planes, int frame,
                             std::vector<std::array<float, 3>>* albedo_of_geometry);

// The maps and placements of frame f, as render_coherent takes them.
std::vector<PlacedStack> placed_stacks(const std::vector<SceneObject>& objects, int frame);

// The smallest sphere found around the placed objects' bounding spheres at frame f (centre: the
// middle of their bounding box; radius: the farthest sphere's reach from it).
void scene_bounds(const std::vector<SceneObject>& objects, int frame, Vec3* center, double* radius);

}  // namespace sf::scene

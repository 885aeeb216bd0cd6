#pragma once
// Embree-backed ray casting over a SceneGeometry: triangle meshes and analytic spheres.
// Thread-safe after construction (any number of threads may cast rays at once).
#include <memory>
#include <optional>

#include "scene_geometry.hpp"

namespace sf::scene {

// Ray masks: the ground (floor, terrain) and everything else.
inline constexpr unsigned kMaskGround = 1u;
inline constexpr unsigned kMaskOccluders = 2u;
inline constexpr unsigned kMaskAll = kMaskGround | kMaskOccluders;

struct Hit {
  double t = 0.0;
  Vec3 normal;          // unit geometric normal, facing the incoming ray (surfaces are two-sided)
  unsigned object = 0;  // geometry index: meshes first, then spheres
};

class RayTracer {
 public:
  explicit RayTracer(const SceneGeometry& scene);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  // Nearest hit with t in (t_min, t_max) on geometry whose mask shares a bit with `mask`.
  std::optional<Hit> closest(const Ray& ray, double t_min, double t_max, unsigned mask = kMaskAll) const;
  // True when anything with t in (t_min, t_max) blocks the ray.
  bool occluded(const Ray& ray, double t_min, double t_max, unsigned mask = kMaskAll) const;
  // The first `hits` surface crossings along each of `count` rays, in packets of 16 coherent
  // rays: t[r * hits + h] is the h-th hit of ray r, +infinity when there is none. A later hit is
  // searched from `gap` past the earlier one, so coincident surfaces count once.
  void hits_along(const Ray* rays, size_t count, int hits, double gap, double* t) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sf::scene

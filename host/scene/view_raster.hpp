#pragma once
// Depth layers of triangle meshes seen along an orthographic view, by rasterisation: for every
// texel centre of an M x M map, the `hits` nearest surface crossings. The stacks of coherent
// shadow maps take it for meshes (thousands of views of one object: the vertices are projected
// once a view, and most triangles cover no texel centre and are rejected by their bounds), and
// Embree ray casts for analytic spheres; both give the same depths at texel centres.
#include <cstdint>
#include <vector>

#include "scene_geometry.hpp"

namespace sf::scene {

// An orthographic view: the map spans [-half, half]^2 around `centre` across right and up, depth
// is the distance along -dir from the plane through centre + half_depth dir.
struct OrthoView {
  Vec3 centre, dir, right, up;
  double half = 1.0;        // half the map's side, world units
  double half_depth = 1.0;  // where depth 0 lies along dir from the centre
  int resolution = 1;       // M
};

// 10 bits of each coordinate interleaved (x lowest): nearby points get nearby codes.
uint32_t morton(uint32_t x, uint32_t y, uint32_t z);

class ViewRasterizer {
 public:
  // The meshes of `object` (its analytic spheres are not rasterised: has_spheres()).
  explicit ViewRasterizer(const SceneGeometry& object);
  bool has_spheres() const { return has_spheres_; }

  // t[texel * hits + h] (texel = y M + x, the centre at ((x + 1/2)/M, (y + 1/2)/M) of the map):
  // the h-th nearest crossing, +infinity when there is none. Crossings within `gap` of a nearer
  // one count once. Coverage is decided exactly: vertices snap to 1/256 texel and edge functions
  // are 64-bit integers with a top-left rule, so a sample on an edge shared by two triangles is
  // covered by exactly one of them and a closed mesh has no cracks or doubled surfaces.
  void render(const OrthoView& view, int hits, double gap, std::vector<double>& t) const;

  // The meshes as render() walks them (vertices in Morton order, triangles by their first
  // vertex): the device rasteriser takes the same order (view_raster_device.hpp).
  const std::vector<Vec3>& vertices() const { return vertices_; }
  const std::vector<std::array<uint32_t, 3>>& triangles() const { return triangles_; }

 private:
  std::vector<Vec3> vertices_;
  std::vector<std::array<uint32_t, 3>> triangles_;
  bool has_spheres_ = false;
};

}  // namespace sf::scene

#pragma once
// The two views of a generated scene: the orthographic (directional) light that renders the
// shadow map, and the perspective camera that sees the receivers.
#include "scene_geometry.hpp"
#include "scene_math.hpp"

namespace sf::scene {

// Shadow-map coordinates of a point (methods.md sec. 1): u along `right`, v along `down`
// (row 0 = first row of the file), d = (distance along forward from the near plane)/(far-near).
struct LightCoords {
  double u = 0.0;
  double v = 0.0;
  double d = 0.0;
};

// Orthographic light with the orthonormal basis (right, down, forward), right x down = forward.
// A point p has light-space coordinates (dot(p,right), dot(p,down), dot(p,forward)); the shadow
// map covers [right_range] x [down_range] and depths [near_plane, far_plane].
struct OrthoLight {
  Vec3 forward;  // light direction (unit), pointing from the light into the scene
  Vec3 right;
  Vec3 down;
  Interval right_range;
  Interval down_range;
  double near_plane = 0.0;
  double far_plane = 1.0;

  // Fits a frustum around the whole scene: square extents (square texels on a square map)
  // centred on the scene's footprint, near/far just enclosing the geometry; every range is
  // widened by `margin` times its length on each side.
  static OrthoLight fit(const SceneGeometry& scene, Vec3 direction, double margin);

  // Ray from the near plane through the centre of texel (i, j) of a width x height map.
  Ray texel_ray(int i, int j, int width, int height) const;
  LightCoords project(Vec3 p) const;
  // Light depth range in world units.
  double depth_range() const { return far_plane - near_plane; }
};

// Pinhole camera, square pixels; pixel (x, y) spans [x, x+1] x [y, y+1], row 0 at the top.
struct PerspectiveCamera {
  Vec3 position;
  Vec3 target;
  Vec3 up_hint{0.0, 1.0, 0.0};
  double vertical_fov_degrees = 45.0;
  int width = 640;
  int height = 480;

  // Ray through the continuous image point (x, y) in pixel units (pixel centre: x + 0.5).
  Ray ray_through(double x, double y) const;
};

}  // namespace sf::scene

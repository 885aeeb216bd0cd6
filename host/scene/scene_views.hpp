#pragma once
// The two views of a generated scene: the light that renders the shadow map (orthographic,
// i.e. directional, or perspective, i.e. a spot light) and the camera that sees the receivers.
#include <vector>

#include "scene_geometry.hpp"
#include "scene_math.hpp"

namespace sf::scene {

// Shadow-map coordinates of a point (methods.md sec. 1): u along `right`, v along `down`
// (row 0 = first row of the file), d = (view depth - near) / (far - near), view depth being
// the distance along `forward` (ortho: from the origin plane; perspective: from the light).
struct LightCoords {
  double u = 0.0;
  double v = 0.0;
  double d = 0.0;
};

enum class LightType { Ortho, Perspective };

// Light with the orthonormal basis (right, down, forward), right x down = forward.
struct LightView {
  LightType type = LightType::Ortho;
  Vec3 forward;  // view axis (unit), pointing from the light into the scene
  Vec3 right;
  Vec3 down;
  // Ortho: the map covers [right_range] x [down_range] (world units along right/down).
  Interval right_range;
  Interval down_range;
  // Perspective: apex and full field of view (square map).
  Vec3 position;
  double fov_degrees = 0.0;
  double near_plane = 0.0;  // view depth of d = 0
  double far_plane = 1.0;   // view depth of d = 1

  // Orthographic light along `direction`, fitted to the geometry: square extents centred on
  // the scene's footprint, near/far enclosing the geometry; each range is widened by `margin`
  // times its length on every side.
  static LightView fit_ortho(const SceneGeometry& scene, Vec3 direction, double margin);
  // Spot light at `position` looking at `target`; fov_degrees <= 0 fits the field of view to
  // the geometry. Throws InputError when geometry lies behind or at the light.
  static LightView fit_perspective(const SceneGeometry& scene, Vec3 position, Vec3 target, double fov_degrees,
                                   double margin);

  // Ray through the centre of texel (i, j), and the ray parameter at which it enters the
  // frustum (the near plane).
  Ray texel_ray(int i, int j, int width, int height) const;
  double texel_ray_start(const Ray& ray) const;
  // Normalised depth of the point ray.at(t) (ray from texel_ray).
  double depth_at(const Ray& ray, double t) const;
  LightCoords project(Vec3 p) const;
  double depth_range() const { return far_plane - near_plane; }
  double tan_half_fov() const;

  // The point light of the hard reference: direction from p towards the light and the
  // distance to it (ortho: -forward, up to the near plane).
  Ray towards_light(Vec3 p, double& distance) const;
  // A point of the rectangular area light of sides width (along right) and height (along down),
  // (s, t) in [-1/2, 1/2]^2 along (right, down). Perspective: the rectangle centred on the light
  // position, perpendicular to forward. Ortho: the rectangle in the near plane centred on p's
  // projection onto it (the PCSS model of a directional area light, so that a penumbra across
  // right is width (d_R - d_B) / d_B with depths measured from the near plane, and sides -> 0
  // give the hard reference).
  Vec3 area_light_point(Vec3 p, double width, double height, double s, double t) const;
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

#pragma once
// Renders the images of a generated scene by ray casting with Embree (rows spread over
// threads; every pixel is computed independently and sampled from its own seeded stream, so
// the result does not depend on the thread count).
#include <array>
#include <memory>

#include "shadowfilter/host_image.hpp"

#include "ray_tracer.hpp"
#include "scene_geometry.hpp"
#include "scene_views.hpp"

namespace sf::scene {

struct SceneSetup {
  SceneGeometry geometry;
  LightView light;
  PerspectiveCamera camera;
  int map_width = 512;  // shadow-map size in texels
  int map_height = 512;
  double light_size = 0.2;     // area light's side along the light's right (world units)
  double light_height = -1.0;  // its side along down; < 0: light_size (a square)
  double area_light_height() const { return light_height >= 0.0 ? light_height : light_size; }
  int samples = 64;  // area-light samples per pixel, a square number
  // The soft reference over the whole pixel: each sample's camera ray through a point of its
  // stratum of the pixel, paired with a point of the same stratum of the light (the visibility a
  // renderer's antialiased pixel shows, what footprint lookups estimate); false: every sample
  // from the surface point at the pixel's centre.
  bool pixel_average = false;
  unsigned seed = 1;
  bool progress = true;  // progress bars on stderr for stages over a second
  int threads = 0;       // 0 = hardware concurrency
};

// Camera-view outputs of one pass.
struct CameraImages {
  HostImage receivers;       // u v d (float) f ndl (half); NaN on background
  HostImage reference_hard;  // Y: 1 lit, 0 occluded, 1 background
  HostImage reference_soft;  // Y: fraction of area-light samples visible, 1 background
  // The layered view (view.exr, io::view_channel_names()): world position of the hit P, view
  // depth (distance along the camera's axis), the world offsets dPdx, dPdy across the pixel on
  // the hit's tangent plane (float) and ndl (half); NaN on background. layer_render.hpp turns it
  // into sf::ViewReceivers.
  HostImage view;
};

class SceneRenderer {
 public:
  explicit SceneRenderer(const SceneSetup& setup);
  // Shadow map: 1 channel "Z", linear light depth of the first hit, 1 where nothing is hit.
  HostImage shadow_map() const;
  // Planar receivers: 1 channel "Z", depth of the ground alone (occluders removed) at every
  // texel centre, NaN where the ray misses the ground.
  HostImage receiver_depth() const;
  // receivers, hard and (when with_soft) soft reference in one camera pass.
  CameraImages camera_view(bool with_soft) const;
  // The same for another camera (a frame of a camera path): the scene, light and map stay.
  CameraImages camera_view(const PerspectiveCamera& camera, bool with_soft) const;

  // The hard and (when with_soft) soft references at the world points of a camera view
  // (ViewReceivers: P, the normal across its pixel offsets dPdx x dPdy, turned to face
  // `camera_position`), traced under this renderer's light with pixel (x, y)'s sample stream:
  // what camera_view gives at those points under this light, up to P's float rounding. Images
  // of the view's size (1 on background), as camera_view's.
  CameraImages references_at(const ViewReceivers& view, Vec3 camera_position, bool with_soft) const;

  // Single-point queries (for tests): lit by the point light / fraction of the area light seen.
  bool lit_hard(Vec3 point, Vec3 normal) const;
  // Cosine between the (camera-facing) normal and the direction to the light; <= 0 faces away.
  double n_dot_l(Vec3 point, Vec3 normal) const;
  // The receivers' nx ny nz at a hit (normal_offset.hpp).
  std::array<float, 3> texel_scaled_normal(Vec3 point, Vec3 normal) const;
  double visible_fraction(Vec3 point, Vec3 normal, uint64_t stream) const;
  bool sees_light_point(Vec3 point, Vec3 normal, double s, double t) const;
  // SceneSetup::pixel_average's soft value of pixel (x, y) (1 where no stratum's ray hits).
  double pixel_visible_fraction(const PerspectiveCamera& camera, int x, int y, uint64_t stream) const;
  const RayTracer& tracer() const { return tracer_; }

 private:
  template <class RowFn>
  void for_each_row(const char* label, int rows, int width, const RowFn& row_fn) const;
  // The pixel's footprint: f and the Jacobian columns (dudx, dvdx), (dudy, dvdy) in texels.
  struct Footprint {
    double f = 0;
    std::array<double, 4> jacobian{};
  };
  Footprint footprint_texels(const PerspectiveCamera& camera, int x, int y, Vec3 point, Vec3 normal) const;
  void pixel_offsets(const PerspectiveCamera& camera, int x, int y, Vec3 point, Vec3 normal, double distance, Vec3& dx,
                     Vec3& dy) const;
  const SceneSetup& setup_;
  RayTracer tracer_;
  int strata_ = 0;
  double offset_ = 0.0;  // shadow-ray origin offset along the normal
};

// Smallest (ground depth - shadow-map depth) over texels where an occluder hides the ground:
// the occluder-ground gap in normalised light depth. +infinity when nothing is shadowed.
double min_occluder_floor_gap(const HostImage& shadow_map, const HostImage& receiver_depth);

}  // namespace sf::scene

#pragma once
// Renders the images of a generated scene by analytic ray casting (rows spread over threads;
// every pixel is computed independently, so the result does not depend on the thread count).
#include "shadowfilter/host_image.hpp"

#include "scene_geometry.hpp"
#include "scene_views.hpp"

namespace sf::scene {

struct SceneSetup {
  SceneGeometry geometry;
  OrthoLight light;
  PerspectiveCamera camera;
  int map_width = 512;   // shadow-map size in texels
  int map_height = 512;
};

// Shadow map: 1 channel "Z", linear light depth of the first hit, 1 where nothing is hit.
HostImage render_shadow_map(const SceneSetup& setup);

// Planar receivers: 1 channel "Z", light depth of the floor alone (occluders removed) at every
// texel centre, NaN where the ray misses the floor.
HostImage render_receiver_depth(const SceneSetup& setup);

// Camera-view receivers: channels u, v, d (float) and f (half): the primary hit projected into
// light space and its footprint in level-0 shadow-map texels; all NaN on background pixels.
HostImage render_receivers(const SceneSetup& setup);

// Camera-view ray-traced hard-shadow visibility "Y": 1 lit, 0 occluded, 1 on background.
HostImage render_reference_hard(const SceneSetup& setup);

// Smallest (floor depth - shadow-map depth) over texels where an occluder hides the floor:
// the occluder-floor gap in normalised light depth. +infinity when nothing is shadowed.
double min_occluder_floor_gap(const HostImage& shadow_map, const HostImage& receiver_depth);

}  // namespace sf::scene

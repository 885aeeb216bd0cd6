#pragma once
// The views of a coherent stack rasterised on the device (kernels/coherent/raster.cl;
// docs/coherent.md, "Views on the device"): view_raster.hpp's exact coverage (snapped vertices,
// 64-bit integer edge functions, the top-left rule) and depth planes in double precision, the
// two (or three) nearest crossings of every texel centre, quantised into the maps that
// render_stack writes for triangle meshes, byte for byte. The maps stay on the device for its
// compression (coherent::compress_on_device).
#include <cstddef>

#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/runtime.hpp"

#include "scene_geometry.hpp"

namespace sf::scene {

struct DeviceRasterStats {
  double seconds = 0.0;    // the device's passes and the host's fallback views, wall time
  size_t host_views = 0;   // views whose texels held more crossings than a list: rendered on the host
  size_t batch_views = 0;  // views a batch renders
};

// Every view of `layout` (map i = view enumerate_views(layout)[i]) into a new DeviceDualDepth.
// InputError when the object has analytic spheres (rasterised meshes only: --renderer embree
// ray-casts them) or the device lacks cl_khr_fp64 (the depths are double, as the host's).
coherent::DeviceDualDepth render_stack_on_device(Runtime& rt, const SceneGeometry& object,
                                                 const coherent::StackLayout& layout,
                                                 DeviceRasterStats* stats = nullptr);

}  // namespace sf::scene

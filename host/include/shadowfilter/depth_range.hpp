#pragma once
// The depth range (map_range.hpp) of a map on the host or on the device.
#include <cstddef>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/runtime.hpp"
#include "shadowfilter/map_range.hpp"

namespace sf {

// Least and largest finite texel of a one-channel map (non-finite texels are skipped; a map with
// none finite gives min > max).
MapRange depth_range(const HostImage& depth);

// The same of `texels` floats on the device (kernels/depth_range.cl), after `wait`. Blocking: it
// reads a few kilobytes of per-work-item results back and finishes the reduction on the host.
MapRange depth_range(Runtime& rt, const cl::Buffer& depth, size_t texels, const EventList* wait = nullptr);

}  // namespace sf

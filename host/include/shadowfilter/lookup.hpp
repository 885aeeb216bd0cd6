#pragma once
// Footprint lookups of a filtered basis: trilinear over a mip chain, a box through a
// summed-area table (methods.md sec. 2-3; docs/lookups.md). A thin typed wrapper in the argument order of
// device_types.hpp: buffers are the caller's, every call enqueues after `wait` and returns its last command's event.
#include "shadowfilter/device_types.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// What a footprint lookup reads besides level 0 (empty buffers where not needed).
struct LookupBuffers {
  Lookup kind = Lookup::Bilinear;
  cl::Buffer chain;          // mips: the mip chain of the filtered basis
  cl::Buffer sat;            // sat: the summed-area table of the filtered basis
  cl::Buffer footprint;      // per receiver f in level-0 texels; empty = 1 everywhere
  cl::Buffer jacobian;       // DeviceReceivers::jacobian; empty = isotropic at footprint
  int max_anisotropy = 1;    // with jacobian: the most probes (LookupOptions::max_anisotropy; 1 = isotropic)
  cl::Buffer level_offsets;  // joined mips: mip_level_offsets (method_kernels.hpp); empty = built per call
};
// The shape.channels filtered values of `count` receivers (method-agnostic): out holds
// shape.channels planes of count floats. Used by tests and by callers with their own methods.
cl::Event enqueue_lookup_points(Runtime& rt, Storage storage, const ImageShape& shape, size_t count,
                                const LookupBuffers& lookup, const cl::Buffer& level0, const cl::Buffer& u,
                                const cl::Buffer& v, const cl::Buffer& out, const EventList* wait = nullptr);

}  // namespace sf

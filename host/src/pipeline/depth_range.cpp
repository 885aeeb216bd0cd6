// The depth range of a map (map_range.hpp): a host scan, or a device reduction that reads one
// (min, max) pair per work-item back (kernels/depth_range.cl).
#include "shadowfilter/depth_range.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "cl_errors.hpp"
#include "launch.hpp"

namespace sf {
namespace {

// At most this many work-items: enough to fill a GPU's compute units with long runs, and a
// read-back of 8 KiB.
constexpr size_t kMaxItems = 1024;
// Texels per work-item at least: shorter runs cost more in launch and read-back than they save.
constexpr size_t kMinRun = 4096;

MapRange empty_range() { return {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}; }

}  // namespace

MapRange depth_range(const HostImage& depth) {
  MapRange r = empty_range();
  for (float z : depth.data)
    if (std::isfinite(z)) {
      r.min = std::min(r.min, z);
      r.max = std::max(r.max, z);
    }
  return r;
}

MapRange depth_range(Runtime& rt, const cl::Buffer& depth, size_t texels, const EventList* wait) try {
  if (texels == 0) return empty_range();
  const size_t items = std::clamp<size_t>(texels / kMinRun, 1, kMaxItems);
  const cl_ulong per_item = (texels + items - 1) / items;
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, items * 2 * sizeof(float));
  cl::Kernel k(rt.program({"depth_range.cl"}, detail::BuildOptions().str()), "sf_depth_range");
  detail::KernelArgs(k).buffer(depth).value(cl_ulong(texels)).value(per_item).buffer(out);
  cl::Event done;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(items), cl::NullRange, wait, &done);
  std::vector<float> pairs(items * 2);
  const EventList after{done};
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data(), &after);
  MapRange r = empty_range();
  for (size_t i = 0; i < items; ++i) {
    r.min = std::min(r.min, pairs[2 * i]);
    r.max = std::max(r.max, pairs[2 * i + 1]);
  }
  return r;
} catch (const cl::Error& e) {
  detail::throw_device_error("depth_range", e);
}

}  // namespace sf

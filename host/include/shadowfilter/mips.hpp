#pragma once
// Mip pyramids of basis images and of the raw depth (methods.md sec. 2; docs/lookups.md;
// kernels/pyramid.cl). A thin typed wrapper in the argument order of device_types.hpp: buffers are the
// caller's, every call enqueues after `wait` and returns its last command's event.
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// Level 0 is the caller's image; levels 1 .. top live one after the other in a "chain" buffer,
// each as `channels` planes of width x height values (kernels/pyramid.cl).
struct MipLevel {
  int width = 0, height = 0;
  size_t offset = 0;  // values from the start of the chain (levels >= 1; 0 for level 0)
};
struct MipLayout {
  int channels = 1;
  std::vector<MipLevel> levels;  // levels[0] = the full image
  size_t chain_values = 0;       // values in the chain (levels >= 1), 0 for a 1x1 image
  int top() const { return static_cast<int>(levels.size()) - 1; }
};
MipLayout mip_layout(int width, int height, int channels);

// Reduction of 2x2 texels: the mean for basis images, max / min for the z-max / z-min pyramids
// of the raw depth (conservative: every texel bounds the level-0 texels it covers).
enum class Reduce { Mean = 0, Max = 1, Min = 2 };

// Builds levels 1 .. top of `level0` (shape.channels planes in `storage`) into `chain` (at least
// mip_layout(...).chain_values values, never less than one). Two launches at most for maps up
// to 4096x4096 (32x32 tiles make five levels per launch; one work-item per channel finishes
// the levels of 128x128 and below).
// How the chain is built (docs/gpu.md, "Launch shapes"); every build gives the same max / min
// chains and mean chains within the storage's rounding. family Cpu: the 32x32 tiles (one item
// per four) and the per-channel tail; Gpu: work-groups of 16x16 items, one per texel of the next
// level, five levels per launch through local memory; Auto: by device type. The family and the
// items per Gpu group are ScheduleOptions::family and gpu_work_group (0: the table's 256; a power
// of two: the square below it, 8x8 for 64 or 128), as the blur and the SAT take them.
cl::Event enqueue_pyramid(Runtime& rt, Reduce op, Storage storage, const ScheduleOptions& schedule,
                          const ImageShape& shape, const cl::Buffer& level0, const cl::Buffer& chain,
                          cl::Event* first = nullptr, const EventList* wait = nullptr);

}  // namespace sf

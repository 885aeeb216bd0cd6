#pragma once
// Filtering a sequence of host frames on one warm device: what sf::filter() does for one frame,
// without paying per frame for what frames share. The pipeline and the device buffers are
// allocated for the first frame and reused while the map's size and the receivers' count repeat
// (reallocated when either changes); programs come from the runtime's cache.
//
// Host memory. On a device that shares the host's memory (a CPU device, or one reporting
// CL_DEVICE_HOST_UNIFIED_MEMORY) the frame's own vectors are the kernels' buffers
// (CL_MEM_USE_HOST_PTR; the visibility is made visible to the host by map/unmap), so no frame
// pays a copy into the driver's pages. Elsewhere each frame is copied into buffers allocated once.
//
// A FrameFilter is not thread-safe: one thread runs frames while others decode and encode files
// (the CLI's batch mode, host/cli/filter_batch.cpp).
#include <memory>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// Convenience for host data (what the CLI uses): uploads, runs, downloads. The map's depth range
// (FilterOptions::depth_range, when unset) comes from the host copy, so a lookup that cannot
// hold it is refused before anything runs.
struct FilterResult : VisibilityResult {
  // ESM classification (when asked): the mask (1 = flagged, receivers' size) and its count.
  bool classified = false;
  HostImage flags;
  size_t flagged = 0;
};
FilterResult filter(std::shared_ptr<Runtime> runtime, const FilterOptions& options, const HostImage& depth,
                    const Receivers& receivers);

// Frames of one size after another on one Pipeline (sf::filter runs one through it).
class FrameFilter {
 public:
  enum class HostMemory {
    Auto,      // zero-copy where the device shares the host's memory, else copies
    Copy,      // always copy into device buffers allocated once
    ZeroCopy,  // always wrap the frame's vectors (CL_MEM_USE_HOST_PTR)
  };
  // Validates the options (InputError) before any frame; allocates nothing until the first one.
  FrameFilter(std::shared_ptr<Runtime> runtime, FilterOptions options, HostMemory memory = HostMemory::Auto);
  ~FrameFilter();
  FrameFilter(const FrameFilter&) = delete;
  FrameFilter& operator=(const FrameFilter&) = delete;

  // One frame: the same visibility, flags and counts as filter(runtime, options, depth,
  // receivers), bit for bit. The map's depth range (for the lookups it limits) comes from
  // FilterOptions::depth_range when set, else from this frame's host copy; a frame its lookup
  // cannot hold is refused (InputError) and the next frame may still run.
  FilterResult run(const HostImage& depth, const Receivers& receivers);

  bool zero_copy() const { return zero_copy_; }
  // How many times the frame buffers were (re)allocated: 1 after the first frame, one more per
  // change of the map's size or the receivers' count or kind (the pipeline's own buffers are
  // reallocated with the map's size only).
  int allocations() const { return allocations_; }

 private:
  struct Buffers;
  void prepare(const HostImage& depth, const Receivers& receivers);
  std::shared_ptr<Runtime> rt_;
  FilterOptions options_;
  bool zero_copy_ = false;
  int allocations_ = 0;
  std::unique_ptr<Pipeline> pipe_;
  std::unique_ptr<Buffers> buffers_;
};

}  // namespace sf

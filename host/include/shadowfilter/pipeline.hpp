#pragma once
// The filtering pipeline on device buffers: depth -> basis -> blur -> reconstruct.
// It owns only its intermediate basis images; depth, receivers and the visibility output are
// the caller's buffers, and every step returns an event so callers can chain their own work.
#include <memory>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/kernels.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf {

struct StageTimes {  // device seconds from profiling events (0 on non-profiling queues)
  double transform = 0, blur = 0, reconstruct = 0, upload = 0, download = 0;
  double pyramid = 0, sat = 0, zmax = 0, classify = 0;  // footprint lookups, ESM classification
};

// Receivers on the device. Grid mode (one receiver per shadow-map texel) needs d only.
struct DeviceReceivers {
  bool grid = false;
  size_t count = 0;
  cl::Buffer u, v, d;
  cl::Buffer f;  // footprints in level-0 texels (points mode); empty = 1 for every receiver
};

class Pipeline {
 public:
  // Allocates the basis images for a width x height shadow map. Throws InputError when the
  // options are invalid or the images do not fit the device.
  Pipeline(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height);

  // Transform + blur of a depth map (width*height floats, linear [0,1]).
  cl::Event prefilter(const cl::Buffer& depth, const EventList* wait = nullptr);
  // Visibility per receiver into `visibility` (receivers.count floats).
  cl::Event reconstruct(const DeviceReceivers& receivers, const cl::Buffer& visibility,
                        const EventList* wait = nullptr);

  // The filtered basis of the last prefilter (always the same buffer; with mips a sub-buffer
  // of the one that holds the mip chain too).
  const cl::Buffer& basis() const { return basis_; }
  ImageShape basis_shape() const { return shape_; }
  const MethodDesc& method() const { return *method_; }
  const FilterOptions& options() const { return options_; }
  size_t device_bytes() const { return 2 * shape_.bytes() + lookup_bytes_; }
  // ESM classification: one uchar per receiver of the last reconstruct (1 = flagged), or an
  // empty buffer when the options classify nothing.
  const cl::Buffer& flags() const { return flags_; }
  // Stage times of the last prefilter/reconstruct (waits for their events).
  StageTimes times() const;

 private:
  std::shared_ptr<Runtime> rt_;
  FilterOptions options_;
  const MethodDesc* method_;
  ImageShape shape_;
  cl::Buffer basis_, scratch_;
  cl::Event transform_done_;
  BlurEvents blur_done_;
  cl::Event reconstruct_done_;
  // Footprint lookups and ESM classification (pyramids.hpp), built only when the options ask.
  void allocate_lookups();
  size_t lookup_bytes_ = 0;
  cl::Buffer mips_;  // mips: level 0 (basis_) and the chain (chain_) in one buffer
  cl::Buffer level_offsets_;  // mips: the reconstruction's level-offset table of mips_
  cl::Buffer chain_, sat_, sat_bands_, zmax_chain_, depth_, flags_;
  size_t flags_count_ = 0;
  PassEvents pyramid_done_, sat_done_, zmax_done_;
  cl::Event classify_done_;
};

// Checks that `bytes` in one buffer and `total` bytes overall fit the runtime's device.
void check_fits_device(const Runtime& rt, size_t largest_buffer, size_t total, const std::string& what);

// Convenience for host data (what the CLI uses): uploads, runs, downloads.
struct FilterResult {
  HostImage visibility;  // receivers.width x receivers.height, 1 channel
  StageTimes times;
  size_t background = 0;  // receivers with non-finite depth (output 1)
  size_t outside = 0;     // receivers outside the light frustum (output 1)
  // ESM classification (when asked): the mask (1 = flagged, receivers' size) and its count.
  bool classified = false;
  HostImage flags;
  size_t flagged = 0;
  size_t device_bytes = 0;
};
FilterResult filter(std::shared_ptr<Runtime> runtime, const FilterOptions& options,
                    const HostImage& depth, const Receivers& receivers);

}  // namespace sf

#pragma once
// ESM failure classification as an optional stage after the reconstruction (Annen 2008 ch. 7.3,
// kernels/esm_classify.cl): what it allocates, the z-max pyramid it builds from the raw depth,
// the kernel that flags receivers and replaces their visibility, and its flags. A Pipeline runs
// one when FilterOptions::esm_classify asks for it; a caller with its own reconstruction may run
// one itself on the pipeline's tables. Only methods the registry marks classifiable take it.
#include <memory>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// The classification kernel (a thin typed wrapper in the argument order of device_types.hpp).
// Flags receivers whose lookup support may hold texels behind them (zmax: some texel z with
// z > d + offset, from the dilated z-max pyramid; threshold: exp(-c d) bar(B) > 1 + eps) and replaces
// their visibility by a 2x2 PCF of the ESM test on the raw depth, against the receiver's plane
// (FilterOptions::receiver_plane; receiver_row as DeviceReceivers::row). flags: one uchar per
// receiver.
// `zmax_base` and `zmax_chain` are enqueue_zmax_pyramid's (zmax mode only).
struct ClassifyInputs {
  cl::Buffer depth, zmax_base, zmax_chain;
  cl::Buffer basis;  // level 0 of the filtered basis (threshold mode)
  LookupBuffers lookup;
  int width = 0, height = 0;
};
cl::Event enqueue_esm_classify_points(Runtime& rt, const FilterOptions& opt, size_t count, int receiver_row,
                                      const ClassifyInputs& in, const cl::Buffer& u, const cl::Buffer& v,
                                      const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                      const EventList* wait = nullptr);
cl::Event enqueue_esm_classify_grid(Runtime& rt, const FilterOptions& opt, const ClassifyInputs& in,
                                    const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                    const EventList* wait = nullptr);
// The dilated z-max pyramid that zmax classification reads (kernels/esm_classify.cl): `base` is
// `depth` max-filtered over the blur's (2R+1)^2 window (enqueue_max_filter; R = opt.blur.radius,
// W * H floats; with R = 0 no base is needed: pass an empty buffer and the depth is the base),
// `chain` the Reduce::Max pyramid of the base (mip_layout(W, H, 1).chain_values floats). Every
// level-k texel then holds the max depth over its 2^k block widened by R, and a receiver reads
// 1 to 4 texels (8 for trilinear lookups between odd-sided levels) whatever R and its footprint.
// Returns the last command's event; first: the first.
cl::Event enqueue_zmax_pyramid(Runtime& rt, const FilterOptions& opt, int width, int height, const cl::Buffer& depth,
                               const cl::Buffer& base, const cl::Buffer& chain, cl::Event* first = nullptr,
                               const EventList* wait = nullptr);
// Bytes of the base buffer enqueue_zmax_pyramid needs (0 with R = 0).
size_t zmax_base_bytes(const FilterOptions& opt, int width, int height);

// The threshold eps in effect: opt.esm_classify.threshold_eps, or when negative the automatic
// exp(c offset)(1 + 1e-5) - 1, which makes threshold flag a subset of zmax (docs/lookups.md).
double esm_threshold_eps(const FilterOptions& opt);

class ClassifyStage {
 public:
  // Adds the stage's buffers to `plan` (the z-max base and chain in zmax mode; one flag byte per
  // receiver). Throws InputError when the options classify with a method that cannot.
  static void add_to_plan(const FilterOptions& options, int width, int height, BufferPlan& plan);

  ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height);
  // Allocates what `plan` holds for the stage (a plan add_to_plan filled, e.g. the Pipeline's).
  ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height, const BufferPlan& plan);

  // Before reconstruction: the dilated z-max pyramid of the raw depth (zmax mode), after `wait`. Returns
  // the pyramid's last event (an empty event when the mode needs none). Keeps `depth` for classify().
  cl::Event prepare(const cl::Buffer& depth, const EventList* wait);
  // After the reconstruction's event in `wait`: flags the receivers and rewrites their
  // visibility; `basis` and `lookup` are the tables the reconstruction read.
  cl::Event classify(const cl::Buffer& basis, const LookupBuffers& lookup, const DeviceReceivers& receivers,
                     const cl::Buffer& visibility, const EventList* wait);

  // One uchar per receiver of the last classify() (1 = flagged).
  const cl::Buffer& flags() const { return flags_; }
  // Seconds of the last z-max pyramid (with its max filter) and classification (profiling queues),
  // and of faulting in the buffers the frame was the first to use (resident).
  void add_times(StageTimes& t) const;

 private:
  std::shared_ptr<Runtime> rt_;
  FilterOptions options_;
  int width_, height_;
  cl::Buffer zmax_base_, zmax_chain_, depth_, flags_;
  size_t flags_count_ = 0;
  cl::Event zmax_first_, zmax_done_;
  cl::Event classify_done_;
  // Faulting in the stage's new buffers on a CPU device (StageTimes::resident): the z-max
  // buffers before the first frame, the flags where a frame (re)allocates them.
  cl::Event resident_first_, resident_done_, flags_resident_first_, flags_resident_done_;
  int frames_ = 0;
};

}  // namespace sf

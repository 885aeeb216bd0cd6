#pragma once
// The filtering pipeline on device buffers: depth -> basis -> blur -> lookup tables -> reconstruct.
//
// Ownership. A Pipeline owns its intermediate buffers only (the basis images and whatever the
// lookup needs; Pipeline::plan lists them before anything is allocated). The depth map, the
// receivers and the visibility output are the caller's buffers: the pipeline reads or writes
// them only inside the commands it enqueues and keeps no reference past the next prefilter().
// It keeps the Runtime (context, queue, program cache) alive through its shared_ptr.
//
// Queues and events. Every command goes to runtime->queue() after the caller's `wait` events and
// each call returns the event of its last command, so a caller chains its own kernels without a
// host round trip. Every dependency inside a call is an explicit event, so out-of-order queues
// (CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE) work: the caller orders its own commands against the
// returned events. Two calls on one Pipeline must still be ordered by the caller: reconstruct()
// waits on the event prefilter() returned (pass it in `wait`), and the next prefilter() must wait
// on the last reconstruct(), as it overwrites the basis that one reads.
//
// Threads. A Pipeline is not thread-safe: one thread at a time. Different Pipelines may run on
// different threads, also on one Runtime (its program cache is locked; OpenCL queues are
// thread-safe, and every call makes its own cl::Kernel objects).
//
// Sub-buffers. Any cl::Buffer argument may be a sub-buffer (clCreateSubBuffer): depth, receiver
// and visibility data then start at the sub-buffer's origin. OpenCL requires the origin to be a
// multiple of CL_DEVICE_MEM_BASE_ADDR_ALIGN (sub_buffer() in runtime.hpp checks it and says so);
// which is at least 128 bytes on every full-profile device, and covers every access the
// kernels make (the widest is 64 bytes).
//
// Errors. InputError for options or sizes the device cannot take, DeviceError for OpenCL
// failures (errors.hpp); no cl::Error leaves the library.
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

class ClassifyStage;

class Pipeline {
 public:
  // What the constructor would allocate, without allocating: validates the options like the
  // constructor (InputError) but does not check that they fit the device.
  static BufferPlan plan(const Runtime& rt, const FilterOptions& options, int width, int height);

  // Allocates plan(runtime, options, width, height) for a width x height shadow map. Throws
  // InputError when the options are invalid or the buffers do not fit the device.
  Pipeline(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height);

  // Transform + blur of a depth map (width*height floats, linear [0,1]). Where the lookup's
  // limit depends on the map's depth range (esm, evsm with sat: MethodDesc::sat_limit) and
  // FilterOptions::depth_range is unset, it first reads the map's range back from the device (a
  // blocking reduction, depth_range.hpp) and throws InputError, enqueuing nothing, when the
  // lookup cannot hold it; state the range in the options to keep prefilter() asynchronous.
  cl::Event prefilter(const cl::Buffer& depth, const EventList* wait = nullptr);
  // States the depth range of the maps the next prefilter() calls read (a caller that knows it
  // from its host copy, as FrameFilter does per frame): checked against the lookup's limit now
  // (InputError, the pipeline unchanged) and prefilter() then needs no device reduction.
  void set_depth_range(const MapRange& range);
  // Visibility per receiver into `visibility` (rx.count floats).
  cl::Event reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const EventList* wait = nullptr);

  // The filtered basis of the last prefilter (always the same buffer; with mips a sub-buffer
  // of the one that holds the mip chain too).
  const cl::Buffer& basis() const { return basis_; }
  ImageShape basis_shape() const { return shape_; }
  // The tables the lookup of these options reads besides basis() (kind, mip chain, SAT, level
  // offsets; empty buffers where not needed), valid after the prefilter's event: what a
  // caller's own kernel passes to sf_lookup (embed.hpp).
  LookupBuffers lookup_tables() const;
  const MethodDesc& method() const { return *method_; }
  const FilterOptions& options() const { return options_; }
  // Bytes of the buffers this pipeline allocated (plan().total(); the ESM flags not included).
  size_t device_bytes() const { return plan_.total(); }
  const BufferPlan& buffer_plan() const { return plan_; }
  // ESM classification: one uchar per receiver of the last reconstruct (1 = flagged), or an
  // empty buffer when the options classify nothing.
  const cl::Buffer& flags() const;
  // Stage times of the last prefilter/reconstruct (waits for their events); after the first
  // prefilter also the faulting in of the buffers the constructor allocated (resident).
  StageTimes times() const;

 private:
  std::shared_ptr<Runtime> rt_;
  FilterOptions options_;
  const MethodDesc* method_;
  ImageShape shape_;
  cl::Buffer basis_, scratch_;
  cl::Event transform_done_;
  cl::Event blur_first_, blur_done_;  // first and last command of each multi-command stage
  cl::Event reconstruct_done_;
  // Footprint lookups (mips.hpp, sat.hpp) and ESM classification (classify.hpp), built only when the
  // options ask.
  BufferPlan plan_;
  cl::Buffer mips_;           // mips: level 0 (basis_) and the chain (chain_) in one buffer
  cl::Buffer level_offsets_;  // mips: the reconstruction's level-offset table of mips_
  cl::Buffer chain_, sat_, sat_bands_;
  cl::Event pyramid_first_, pyramid_done_, sat_first_, sat_done_;
  // The fills that fault in the new buffers on a CPU device (StageTimes::resident), reported
  // with the first frame; prefilters_ counts the frames.
  cl::Event resident_first_, resident_done_;
  int prefilters_ = 0;
  // The optional stage after the reconstruction (classify.hpp), when the options ask for it.
  std::shared_ptr<ClassifyStage> classify_;
};

// Checks that `bytes` in one buffer and `total` bytes overall fit the runtime's device.
void check_fits_device(const Runtime& rt, size_t largest_buffer, size_t total, const std::string& what);

// Receivers that carry ndl and face away from the light (ndl <= 0; NaN = unknown, left alone) get
// visibility 0: their own surface blocks the light, which a shadow map of that surface cannot
// show (it holds the surface's lit side, at about the receiver's depth). Returns how many.
// filter() and soft_filter() apply it (FilterOptions::facing_away_shadowed,
// SoftOptions::facing_away_shadowed); device pipelines leave it to the caller's n.l.
size_t shadow_facing_away(const Receivers& receivers, std::vector<float>& visibility);

}  // namespace sf

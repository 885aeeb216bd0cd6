// FrameFilter (frame_filter.hpp) and filter(), which is one frame of it.
#include "shadowfilter/frame_filter.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "cl_errors.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/footprint.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/normal_offset.hpp"

namespace sf {
namespace {

// Host memory the device reads in place: a CPU device runs on it, and a device that reports
// unified memory maps it without a copy.
bool shares_host_memory(const Runtime& rt) {
  if (rt.info().type == "CPU") return true;
  return rt.device().getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() == CL_TRUE;
}

// The receivers' vectors the reconstruction reads (footprints only for footprint lookups).
bool reads_footprint(const Receivers& rx, const FilterOptions& o) {
  return !rx.grid && rx.has_footprint && o.lookup.kind != Lookup::Bilinear;
}
// ... and their Jacobians, for anisotropic lookups (footprint.hpp).
bool reads_jacobian(const Receivers& rx, const FilterOptions& o) {
  return !rx.grid && rx.has_jacobian && o.lookup.follows_jacobian();
}

// On a CPU device the host's program builds and the kernels share the cores: in a frame's first
// run, a kernel enqueued while the host built the next stage's program took up to 2.5x its own
// time (z-max 6.4 ms against 2.6 ms in a one-shot backyard frame, docs/batch.md). There the
// commands of a frame that allocated (a new map size or receiver kind, whose programs may be new)
// wait on this gate, which opens once all of them are enqueued, every program built: each
// stage's device time is its own. The fills that fault in the new buffers (resident.hpp) were
// enqueued before it and run beside the builds. Other devices, and frames that reuse their
// buffers, start each command as it comes: no gate.
class HostGate {
 public:
  HostGate(const Runtime& rt, bool building) {
    if (building && rt.info().type == "CPU") wait_.push_back(cl::UserEvent(rt.context()));
  }
  HostGate(const HostGate&) = delete;
  HostGate& operator=(const HostGate&) = delete;
  // Open on every way out: an exception after the first gated command leaves none waiting.
  ~HostGate() { open(); }
  // What the frame's first commands wait on: the gate, or nothing.
  const EventList* wait() const { return wait_.empty() ? nullptr : &wait_; }
  void open() {
    if (!wait_.empty()) clSetUserEventStatus(wait_.front()(), CL_COMPLETE);
    wait_.clear();
  }

 private:
  EventList wait_;
};

}  // namespace

// The frame buffers of one map size and receiver count (copy mode; zero-copy mode wraps each
// frame's vectors instead and keeps only the sizes).
struct FrameFilter::Buffers {
  int width = 0, height = 0;
  size_t count = 0;
  bool grid = false, footprint = false, jacobian = false;
  size_t input_bytes = 0;  // the depth map and the receivers on the device (as filter() counts them)
  cl::Buffer depth, u, v, d, f, jac, visibility;
  std::vector<float> jacobian_planes;  // the frame's dudx, dvdx, dudy, dvdy one after the other

  bool fits(const HostImage& map, const Receivers& rx, bool with_footprint, bool with_jacobian) const {
    return map.width == width && map.height == height && rx.count() == count && rx.grid == grid &&
           with_footprint == footprint && with_jacobian == jacobian;
  }
};

FrameFilter::FrameFilter(std::shared_ptr<Runtime> runtime, FilterOptions options, HostMemory memory)
    : rt_(std::move(runtime)), options_(std::move(options)) {
  // The options are checked as the pipeline will check them, before any frame is read.
  validate_options(options_);
  zero_copy_ = memory == HostMemory::ZeroCopy || (memory == HostMemory::Auto && shares_host_memory(*rt_));
}

FrameFilter::~FrameFilter() = default;

// The pipeline follows the map's size, the frame buffers the map's size and the receivers.
void FrameFilter::prepare(const HostImage& depth, const Receivers& receivers) {
  const bool footprint = reads_footprint(receivers, options_);
  const bool jacobian = reads_jacobian(receivers, options_);
  const bool same_map =
      pipe_ && pipe_->basis_shape().width == depth.width && pipe_->basis_shape().height == depth.height;
  if (same_map && buffers_ && buffers_->fits(depth, receivers, footprint, jacobian)) return;
  if (!same_map) {
    pipe_.reset();
    buffers_.reset();
    pipe_ = std::make_unique<Pipeline>(rt_, options_, depth.width, depth.height);
  }
  buffers_.reset();
  const size_t count = receivers.count();
  auto b = std::make_unique<Buffers>();
  b->input_bytes = (depth.data.size() + count * (receivers.grid ? 2 : 4) + (jacobian ? 4 * count : 0)) * sizeof(float);
  check_fits_device(*rt_, std::max(pipe_->basis_shape().bytes(), count * sizeof(float)),
                    pipe_->device_bytes() + b->input_bytes, "this run");
  b->width = depth.width;
  b->height = depth.height;
  b->count = count;
  b->grid = receivers.grid;
  b->footprint = footprint;
  b->jacobian = jacobian;
  if (!zero_copy_) {
    const cl::Context& ctx = rt_->context();
    auto alloc = [&ctx](cl_mem_flags flags, size_t floats) { return cl::Buffer(ctx, flags, floats * sizeof(float)); };
    b->depth = alloc(CL_MEM_READ_ONLY, depth.data.size());
    b->d = alloc(CL_MEM_READ_ONLY, count);
    if (!receivers.grid) {
      b->u = alloc(CL_MEM_READ_ONLY, count);
      b->v = alloc(CL_MEM_READ_ONLY, count);
      if (footprint) b->f = alloc(CL_MEM_READ_ONLY, count);
      if (jacobian) b->jac = alloc(CL_MEM_READ_ONLY, 4 * count);
    }
    b->visibility = alloc(CL_MEM_WRITE_ONLY, count);
  }
  buffers_ = std::move(b);
  ++allocations_;
}

FilterResult FrameFilter::run(const HostImage& depth, const Receivers& given) try {
  Runtime& rt = *rt_;
  if (depth.channels != 1) throw InputError("depth map must have one channel");
  if (depth.data.size() != depth.texels()) throw InputError("depth map data does not match its size");
  // Every lookup moved along its receiver's normal first (normal_offset.hpp): the counts, the
  // lookups and the uploads all see the moved receivers.
  std::optional<Receivers> moved;
  if (const float t = normal_offset(options_); t != 0.0f && given.has_normal)
    moved = offset_along_normals(given, depth.width, depth.height, t);
  const Receivers& receivers = moved ? *moved : given;
  const size_t count = receivers.count();
  if (receivers.d.size() != count || (!receivers.grid && (receivers.u.size() != count || receivers.v.size() != count)))
    throw InputError("receivers' data does not match their size");
  if (receivers.has_jacobian && (receivers.dudx.size() != count || receivers.dvdx.size() != count ||
                                 receivers.dudy.size() != count || receivers.dvdy.size() != count))
    throw InputError("receivers' Jacobian does not match their size");
  const int allocations = allocations_;
  prepare(depth, receivers);
  // The map's depth range from the host copy, where the lookup's limit depends on it: a frame
  // the lookup cannot hold is refused before anything is enqueued, and prefilter() needs no
  // device reduction.
  if (options_.depth_range)
    pipe_->set_depth_range(*options_.depth_range);
  else if (options_.lookup.kind == Lookup::Sat && pipe_->method().sat_limit)
    pipe_->set_depth_range(depth_range(depth));

  FilterResult result;
  for (size_t i = 0; i < count; ++i) {
    if (!std::isfinite(receivers.d[i])) {
      ++result.background;
    } else if (!receivers.grid && !(receivers.u[i] >= 0.0f && receivers.u[i] <= 1.0f && receivers.v[i] >= 0.0f &&
                                    receivers.v[i] <= 1.0f)) {
      ++result.outside;
    }
  }
  result.visibility = HostImage(receivers.width, receivers.height, 1);

  // The frame's inputs as device buffers: the host vectors themselves, or copies into the
  // buffers allocated for this size.
  Buffers& b = *buffers_;
  HostGate gate(rt, allocations_ != allocations);
  EventList uploads;
  auto input = [&](const std::vector<float>& host, const cl::Buffer& allocated) {
    if (zero_copy_)
      return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, host.size() * sizeof(float),
                        const_cast<float*>(host.data()));  // read only: the kernels never write it
    cl::Event e;
    rt.queue().enqueueWriteBuffer(allocated, CL_FALSE, 0, host.size() * sizeof(float), host.data(), gate.wait(), &e);
    uploads.push_back(e);
    return allocated;
  };
  const cl::Buffer depth_buf = input(depth.data, b.depth);
  DeviceReceivers rx;
  rx.grid = receivers.grid;
  rx.count = count;
  rx.row = receivers.grid ? 0 : receivers.width;
  rx.d = input(receivers.d, b.d);
  if (!receivers.grid) {
    rx.u = input(receivers.u, b.u);
    rx.v = input(receivers.v, b.v);
    if (b.footprint) rx.f = input(receivers.f, b.f);
    if (b.jacobian) {
      jacobian_planes(receivers, b.jacobian_planes);
      rx.jacobian = input(b.jacobian_planes, b.jac);
    }
  }
  const cl::Buffer vis = zero_copy_ ? cl::Buffer(rt.context(), CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR,
                                                 count * sizeof(float), result.visibility.data.data())
                                    : b.visibility;

  cl::Event filtered = pipe_->prefilter(depth_buf, uploads.empty() ? gate.wait() : &uploads);
  EventList after{filtered};
  cl::Event rec = pipe_->reconstruct(rx, vis, &after);
  gate.open();
  EventList after_rec{rec};
  cl::Event download;
  if (zero_copy_) {
    // Mapping a CL_MEM_USE_HOST_PTR buffer brings the device's writes into the host vector.
    void* p = rt.queue().enqueueMapBuffer(vis, CL_TRUE, CL_MAP_READ, 0, count * sizeof(float), &after_rec, &download);
    cl::Event unmapped;
    rt.queue().enqueueUnmapMemObject(vis, p, nullptr, &unmapped);
    unmapped.wait();
  } else {
    rt.queue().enqueueReadBuffer(vis, CL_TRUE, 0, count * sizeof(float), result.visibility.data.data(), &after_rec,
                                 &download);
  }
  if (classify_mode(options_) != EsmClassify::None) {
    std::vector<unsigned char> flags(count);
    if (count) rt.queue().enqueueReadBuffer(pipe_->flags(), CL_TRUE, 0, count, flags.data(), &after_rec);
    result.classified = true;
    result.flags = HostImage(receivers.width, receivers.height, 1);
    for (size_t i = 0; i < count; ++i) {
      result.flags.data[i] = flags[i] ? 1.0f : 0.0f;
      result.flagged += flags[i] ? 1 : 0;
    }
  }
  if (options_.facing_away_shadowed) result.facing_away = shadow_facing_away(receivers, result.visibility.data);
  result.times = pipe_->times();
  if (!uploads.empty()) result.times.upload = event_seconds(uploads.front(), uploads.back());
  result.times.download = event_seconds(download);
  result.device_bytes = pipe_->device_bytes() + b.input_bytes + count * sizeof(float);
  return result;
} catch (const cl::Error& e) {
  detail::throw_device_error("FrameFilter::run", e);
}

FilterResult filter(std::shared_ptr<Runtime> runtime, const FilterOptions& options, const HostImage& depth,
                    const Receivers& receivers) {
  return FrameFilter(std::move(runtime), options).run(depth, receivers);
}

}  // namespace sf

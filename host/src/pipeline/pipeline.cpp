#include "shadowfilter/blur.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "cl_errors.hpp"
#include "planned_scope.hpp"
#include "resident.hpp"
#include "shadowfilter/classify.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"

namespace sf {

void check_fits_device(const Runtime& rt, size_t largest_buffer, size_t total, const std::string& what) {
  const auto& info = rt.info();
  auto mib = [](size_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MiB"; };
  if (largest_buffer > info.max_alloc_bytes || total > info.global_mem_bytes) {
    std::ostringstream s;
    s << what << " needs " << mib(total) << " (largest buffer " << mib(largest_buffer) << ") but device '"
      << info.device_name << "' allows " << mib(info.max_alloc_bytes) << " per buffer and "
      << mib(info.global_mem_bytes) << " in all";
    throw InputError(s.str());
  }
}

namespace {

// Where the chain starts in the joined mips buffer: after level 0, at the device's sub-buffer
// alignment (CL_DEVICE_MEM_BASE_ADDR_ALIGN).
size_t joined_level0_bytes(const Runtime& rt, const ImageShape& shape) {
  const size_t align = std::max<size_t>(rt.device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8, 4);
  return (shape.bytes() + align - 1) / align * align;
}

// A lookup that cannot hold a map of this depth range and size is refused (methods.hpp).
void require_sat_holds(const FilterOptions& options, const SatMap& map) {
  const std::string why = sat_refusal(options, map);
  if (!why.empty()) throw InputError(why);
}

}  // namespace

// Only what the options need: a mean pyramid for mips, a SAT for sat, a z-max pyramid of the
// depth for zmax classification (raw-depth methods weight their tests directly: none), and the
// blur's scratch only where a basis is blurred.
BufferPlan Pipeline::plan(const Runtime& rt, const FilterOptions& options, int width, int height) try {
  if (width <= 0 || height <= 0)
    throw InputError("shadow map size must be positive, got " + std::to_string(width) + "x" + std::to_string(height));
  validate_options(options);
  const MethodDesc& method = *options.method;
  gaussian_weights(options.blur.radius, options.blur.sigma);  // validates the radius
  // A stated depth range is checked here, before anything is allocated; else prefilter() checks
  // each map's own.
  if (options.depth_range) require_sat_holds(options, SatMap{*options.depth_range, width, height, rt.info().fp64});
  BufferPlan plan;
  plan.shape = {width, height, method.channels(options), method.raw_depth ? 4 : storage_bytes(options.storage)};
  const ImageShape& shape = plan.shape;
  if (shape.plane_texels() * shape.channels > size_t(1) << 31)
    throw InputError("shadow map " + std::to_string(width) + "x" + std::to_string(height) +
                     " is too large (more than 2^31 basis values)");
  auto add = [&plan](const char* name, size_t bytes) { plan.buffers.push_back({name, std::max<size_t>(bytes, 4)}); };
  const Lookup lookup = method.raw_depth ? Lookup::Bilinear : options.lookup.kind;
  if (lookup == Lookup::Mips) {
    // Level 0 (the basis) and the chain in one buffer, one padding value after the chain.
    const MipLayout mips = mip_layout(width, height, shape.channels);
    add("basis+mips", joined_level0_bytes(rt, shape) + (mips.chain_values + 1) * shape.value_bytes);
    add("mip level offsets", mips.levels.size() * sizeof(cl_int));
  } else {
    add("basis", shape.bytes());
  }
  if (options.blur.radius > 0 && !method.raw_depth) add("blur scratch", shape.bytes());
  if (lookup == Lookup::Sat) {
    const SatLayout L = sat_layout(shape);
    add("sat", L.table_floats * sizeof(float));
    add("sat bands", L.band_floats * sizeof(float));
  }
  ClassifyStage::add_to_plan(options, width, height, plan);
  return plan;
} catch (const cl::Error& e) {
  detail::throw_device_error("Pipeline::plan", e);
}

Pipeline::Pipeline(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height) try
    : rt_(std::move(runtime)), options_(std::move(options)), method_(&*options_.method) {
  plan_ = plan(*rt_, options_, width, height);
  shape_ = plan_.shape;
  check_fits_device(*rt_, plan_.largest(), plan_.total(), "the pipeline's buffers");
  auto alloc = [this](const char* name) { return cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, plan_.bytes(name)); };
  if (plan_.bytes("basis+mips")) {
    // The reconstruction addresses every level from one base (kernels.cpp, SF_MIPS_JOINED):
    // basis_ and chain_ are sub-buffers of mips_.
    mips_ = alloc("basis+mips");
    const size_t level0 = joined_level0_bytes(*rt_, shape_);
    basis_ = sub_buffer(*rt_, mips_, 0, shape_.bytes());
    chain_ = sub_buffer(*rt_, mips_, level0, plan_.bytes("basis+mips") - level0);
    level_offsets_ = mip_level_offsets(*rt_, options_.storage, mips_, chain_, shape_);
  } else {
    basis_ = alloc("basis");
  }
  if (plan_.bytes("blur scratch")) scratch_ = alloc("blur scratch");
  if (plan_.bytes("sat")) {
    sat_ = alloc("sat");
    sat_bands_ = alloc("sat bands");
  }
  if (classify_mode(options_) != EsmClassify::None)
    classify_ = std::make_shared<ClassifyStage>(rt_, options_, width, height, plan_);
  // Every buffer's pages in before the first frame (resident.hpp); basis_ and chain_ are parts of mips_.
  resident_done_ =
      detail::fault_in(*rt_, {mips_() ? &mips_ : &basis_, &scratch_, &sat_, &sat_bands_}, &resident_first_);
} catch (const cl::Error& e) {
  detail::throw_device_error("Pipeline::Pipeline", e);
}

cl::Event Pipeline::prefilter(const cl::Buffer& depth, const EventList* wait) try {
  const detail::PlannedScope planned;  // options_ were validated by the plan
  // The fills are reported with the first frame only.
  if (prefilters_++ > 0) resident_first_ = resident_done_ = cl::Event();
  // Without a stated range, a lookup whose limit depends on it measures this map first
  // (blocking) and refuses it before anything is enqueued.
  if (sat_() && !options_.depth_range && method_->sat_limit) {
    const MapRange range = depth_range(*rt_, depth, shape_.plane_texels(), wait);
    require_sat_holds(options_, SatMap{range, shape_.width, shape_.height, rt_->info().fp64});
  }
  // Raw-depth methods (sm, pcf) weight their tests at the lookup: nothing to prefilter.
  const bool blur = options_.blur.radius > 0 && !method_->raw_depth;
  transform_done_ =
      enqueue_transform(*rt_, *method_, options_, shape_.width, shape_.height, depth, blur ? scratch_ : basis_, wait);
  blur_first_ = blur_done_ = pyramid_first_ = pyramid_done_ = sat_first_ = sat_done_ = cl::Event();
  cl::Event filtered = transform_done_;
  if (blur) {  // out of place, scratch_ -> basis_: no copy back
    EventList after{transform_done_};
    blur_done_ = enqueue_blur(*rt_, options_.blur, options_.schedule, options_.storage, shape_, scratch_, basis_,
                              basis_, &blur_first_, &after);
    filtered = blur_done_;
  }
  // The pyramid / SAT of the prefiltered basis, the z-max pyramid of the raw depth.
  EventList done{filtered}, after_filter{filtered};
  if (chain_()) {
    pyramid_done_ = enqueue_pyramid(*rt_, Reduce::Mean, options_.storage, options_.schedule, shape_, basis_, chain_,
                                    &pyramid_first_, &after_filter);
    done.push_back(pyramid_done_);
  }
  if (sat_()) {
    sat_done_ = enqueue_sat(*rt_, options_.storage, {}, options_.schedule, shape_, basis_, sat_, sat_bands_,
                            &sat_first_, &after_filter);
    done.push_back(sat_done_);
  }
  if (classify_) {  // the stage's own pass over the raw depth (z-max pyramid)
    const cl::Event e = classify_->prepare(depth, wait);
    if (e()) done.push_back(e);
  }
  if (done.size() == 1) return filtered;
  cl::Event all;
  rt_->queue().enqueueMarkerWithWaitList(&done, &all);
  return all;
} catch (const cl::Error& e) {
  detail::throw_device_error("Pipeline::prefilter", e);
}

void Pipeline::set_depth_range(const MapRange& range) {
  require_sat_holds(options_, SatMap{range, shape_.width, shape_.height, rt_->info().fp64});
  options_.depth_range = range;
}

cl::Event Pipeline::reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const EventList* wait) try {
  const detail::PlannedScope planned;  // options_ were validated by the plan
  LookupBuffers lookup;
  lookup.kind = method_->raw_depth ? Lookup::Bilinear : options_.lookup.kind;
  // Mips: the joined buffer as the basis, chain_ its sub-buffer (kernels.cpp: SF_MIPS_JOINED).
  const cl::Buffer& rx_basis = mips_() ? mips_ : basis_;
  lookup.chain = chain_;
  lookup.level_offsets = level_offsets_;
  lookup.sat = sat_;
  lookup.footprint = rx.f;
  lookup.jacobian = rx.jacobian;
  lookup.max_anisotropy = options_.lookup.max_anisotropy;
  if (rx.grid) {  // footprint 1 at texel centres: every lookup reads the texel itself
    reconstruct_done_ =
        enqueue_reconstruct_grid(*rt_, *method_, options_, shape_.width, shape_.height, basis_, rx.d, visibility, wait);
  } else {
    reconstruct_done_ = enqueue_reconstruct_points(*rt_, *method_, options_, shape_.width, shape_.height, rx.count,
                                                   rx.row, rx_basis, &lookup, rx.u, rx.v, rx.d, visibility, wait);
  }
  if (!classify_) return reconstruct_done_;
  EventList after{reconstruct_done_};
  return classify_->classify(basis_, lookup, rx, visibility, &after);
} catch (const cl::Error& e) {
  detail::throw_device_error("Pipeline::reconstruct", e);
}

const cl::Buffer& Pipeline::flags() const {
  static const cl::Buffer none;
  return classify_ ? classify_->flags() : none;
}

LookupBuffers Pipeline::lookup_tables() const {
  LookupBuffers t;
  t.kind = method_->raw_depth ? Lookup::Bilinear : options_.lookup.kind;
  t.chain = chain_;
  t.sat = sat_;
  t.level_offsets = level_offsets_;
  t.max_anisotropy = options_.lookup.max_anisotropy;
  return t;
}

StageTimes Pipeline::times() const try {
  StageTimes t;
  if (transform_done_()) t.transform = event_seconds(transform_done_);
  if (blur_done_()) t.blur = event_seconds(blur_first_, blur_done_);
  if (reconstruct_done_()) t.reconstruct = event_seconds(reconstruct_done_);
  if (pyramid_done_()) t.pyramid = event_seconds(pyramid_first_, pyramid_done_);
  if (sat_done_()) t.sat = event_seconds(sat_first_, sat_done_);
  t.resident = detail::resident_seconds(resident_first_, resident_done_);
  if (classify_) classify_->add_times(t);
  return t;
} catch (const cl::Error& e) {
  detail::throw_device_error("Pipeline::times", e);
}

size_t shadow_facing_away(const Receivers& rx, std::vector<float>& visibility) {
  if (!rx.has_ndl) return 0;
  if (rx.ndl.size() != rx.count() || visibility.size() != rx.count())
    throw InputError("shadow_facing_away: receivers and visibility differ in size");
  size_t n = 0;
  for (size_t i = 0; i < visibility.size(); ++i)
    if (rx.ndl[i] <= 0.0f && std::isfinite(rx.d[i])) {
      visibility[i] = 0.0f;
      ++n;
    }
  return n;
}

}  // namespace sf

// ESM failure classification (kernels/esm_classify.cl).
#include <algorithm>
#include <cmath>
#include <string>

#include "cl_errors.hpp"
#include "planned_scope.hpp"
#include "method_build.hpp"
#include "plane_params.hpp"
#include "resident.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/classify.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf {
namespace {

using ClassifyParams = sf_classify_params;  // shared_types.clh

// Receivers per work-item of sf_esm_classify_points_vec (the reconstruction's vector width), or 1
// where the scalar kernel serves (the SAT's box, width 1).
int classify_vector_width(const FilterOptions& opt) {
  return opt.lookup.kind != Lookup::Sat ? detail::reconstruct_vector_width(opt) : 1;
}

cl::Kernel classify_kernel(Runtime& rt, const FilterOptions& opt, const char* name) {
  const MethodDesc& m = *opt.method;
  if (!m.classifiable)
    throw InputError("FilterOptions::esm_classify.mode needs a method whose failures it can classify (esm), got " +
                     opt.method.name());
  detail::validate_unless_planned(m, opt);
  detail::validate(opt.receiver_plane, "FilterOptions::receiver_plane");
  detail::BuildOptions b;
  detail::add_method_options(b, m, opt)
      .lookup(opt.lookup.kind)
      .define("SF_RX_VEC", classify_vector_width(opt))
      .only_kernel(name);
  cl::Program p = rt.program(
      {"common.clh", "storage.clh", m.header, "lookup.clh", "receiver_plane.clh", "esm_classify.cl"}, b.str());
  return cl::Kernel(p, name);
}

ClassifyParams params(const FilterOptions& opt, int width, int height) {
  ClassifyParams c{};
  const MipLayout layout = mip_layout(width, height, 1);
  if (layout.top() >= SF_ZMAX_LEVELS)
    throw InputError("classification: a " + std::to_string(width) + "x" + std::to_string(height) + " map has " +
                     std::to_string(layout.top() + 1) + " mip levels, more than the " + std::to_string(SF_ZMAX_LEVELS) +
                     " the kernel lists");
  c.top = layout.top();
  for (int k = 1; k <= layout.top(); ++k) c.zoff[k] = static_cast<cl_int>(layout.levels[k].offset);
  c.mode = static_cast<cl_int>(classify_mode(opt));
  c.offset = opt.esm_classify.zmax_offset;
  c.log_thresh = static_cast<float>(std::log1p(esm_threshold_eps(opt)));
  return c;
}

// Arguments 0..6 shared by both kernels.
detail::KernelArgs common_args(cl::Kernel& k, const ClassifyInputs& in) {
  detail::KernelArgs a(k);
  a.buffer(in.basis)
      .optional(in.lookup.chain)
      .optional(in.lookup.sat)
      .buffer(in.depth)
      .buffer(in.zmax_base() ? in.zmax_base : in.depth)  // zbase: with R = 0 the depth itself
      .optional(in.zmax_chain)
      .value(in.width)
      .value(in.height);
  return a;
}

void check(const FilterOptions& opt, const ClassifyInputs& in) {
  if (classify_mode(opt) == EsmClassify::None) throw InputError("classification mode is none");
  if (classify_mode(opt) == EsmClassify::ZMax && !in.zmax_chain() && (in.width > 1 || in.height > 1))
    throw InputError("zmax classification needs the z-max pyramid");
  if (classify_mode(opt) == EsmClassify::ZMax && opt.blur.radius > 0 && !in.zmax_base())
    throw InputError("zmax classification with a blur needs the dilated z-max base (enqueue_zmax_pyramid)");
}

}  // namespace

size_t zmax_base_bytes(const FilterOptions& opt, int width, int height) {
  return opt.blur.radius > 0 ? size_t(width) * height * sizeof(float) : 0;
}

cl::Event enqueue_zmax_pyramid(Runtime& rt, const FilterOptions& opt, int width, int height, const cl::Buffer& depth,
                               const cl::Buffer& base, const cl::Buffer& chain, cl::Event* first,
                               const EventList* wait) try {
  const ImageShape shape{width, height, 1, 4};
  if (opt.blur.radius == 0)
    return enqueue_pyramid(rt, Reduce::Max, Storage::F32, opt.schedule, shape, depth, chain, first, wait);
  if (!base()) throw InputError("enqueue_zmax_pyramid: a blur radius > 0 needs the base buffer (zmax_base_bytes)");
  const cl::Event dilated = enqueue_max_filter(rt, opt.blur.radius, opt.schedule, shape, depth, base, first, wait);
  const EventList after{dilated};
  return enqueue_pyramid(rt, Reduce::Max, Storage::F32, opt.schedule, shape, base, chain, nullptr, &after);
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_zmax_pyramid", e);
}

double esm_threshold_eps(const FilterOptions& opt) {
  if (opt.esm_classify.threshold_eps >= 0) return opt.esm_classify.threshold_eps;
  return std::exp(double(opt.esm.c) * opt.esm_classify.zmax_offset) * (1 + 1e-5) - 1;
}

cl::Event enqueue_esm_classify_points(Runtime& rt, const FilterOptions& opt, size_t count, int receiver_row,
                                      const ClassifyInputs& in, const cl::Buffer& u, const cl::Buffer& v,
                                      const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                      const EventList* wait) try {
  check(opt, in);
  const int vec = classify_vector_width(opt);
  cl::Kernel k = classify_kernel(rt, opt, vec > 1 ? "sf_esm_classify_points_vec" : "sf_esm_classify_points");
  common_args(k, in)
      .buffer(u)
      .buffer(v)
      .buffer(d)
      .optional(in.lookup.footprint)
      .buffer(visibility)
      .buffer(flags)
      .value(static_cast<int>(count))
      .value(params(opt, in.width, in.height))
      .bytes(opt.method->pack_params(opt))
      .value(detail::plane_params(opt.receiver_plane, receiver_row));
  cl::Event e;
  const size_t items = std::max<size_t>((count + vec - 1) / vec, 1);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(items), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_esm_classify_points", e);
}

cl::Event enqueue_esm_classify_grid(Runtime& rt, const FilterOptions& opt, const ClassifyInputs& in,
                                    const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                    const EventList* wait) try {
  check(opt, in);
  cl::Kernel k = classify_kernel(rt, opt, "sf_esm_classify_grid");
  common_args(k, in)
      .buffer(d)
      .buffer(visibility)
      .buffer(flags)
      .value(params(opt, in.width, in.height))
      .bytes(opt.method->pack_params(opt))
      .value(detail::plane_params(opt.receiver_plane, 0));
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(in.width, in.height), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_esm_classify_grid", e);
}

}  // namespace sf

namespace sf {

void ClassifyStage::add_to_plan(const FilterOptions& options, int width, int height, BufferPlan& plan) {
  if (classify_mode(options) == EsmClassify::None) return;
  if (!options.method->classifiable)
    throw InputError("FilterOptions::esm_classify.mode needs a method whose failures it can classify (esm), got " +
                     options.method.name());
  if (classify_mode(options) == EsmClassify::ZMax) {
    if (const size_t base = zmax_base_bytes(options, width, height)) plan.buffers.push_back({"zmax base", base});
    plan.buffers.push_back(
        {"zmax chain", std::max<size_t>(mip_layout(width, height, 1).chain_values * sizeof(float), 4)});
  }
  plan.bytes_per_receiver += 1;  // the flags
}

namespace {
BufferPlan stage_plan(const FilterOptions& options, int width, int height) {
  BufferPlan plan;
  ClassifyStage::add_to_plan(options, width, height, plan);
  return plan;
}
}  // namespace

ClassifyStage::ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height)
    : ClassifyStage(runtime, options, width, height, stage_plan(options, width, height)) {}

ClassifyStage::ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height,
                             const BufferPlan& plan) try
    : rt_(std::move(runtime)), options_(std::move(options)), width_(width), height_(height) {
  if (const size_t bytes = plan.bytes("zmax base")) zmax_base_ = cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, bytes);
  if (const size_t bytes = plan.bytes("zmax chain")) zmax_chain_ = cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, bytes);
  resident_done_ = detail::fault_in(*rt_, {&zmax_base_, &zmax_chain_}, &resident_first_);  // resident.hpp
} catch (const cl::Error& e) {
  detail::throw_device_error("ClassifyStage::ClassifyStage", e);
}

cl::Event ClassifyStage::prepare(const cl::Buffer& depth, const EventList* wait) try {
  depth_ = depth;
  zmax_first_ = zmax_done_ = classify_done_ = cl::Event();
  flags_resident_first_ = flags_resident_done_ = cl::Event();
  if (frames_++ > 0) resident_first_ = resident_done_ = cl::Event();  // reported with the first frame
  if (zmax_chain_())
    zmax_done_ =
        enqueue_zmax_pyramid(*rt_, options_, width_, height_, depth, zmax_base_, zmax_chain_, &zmax_first_, wait);
  return zmax_done_;
} catch (const cl::Error& e) {
  detail::throw_device_error("ClassifyStage::prepare", e);
}

cl::Event ClassifyStage::classify(const cl::Buffer& basis, const LookupBuffers& lookup, const DeviceReceivers& rx,
                                  const cl::Buffer& visibility, const EventList* wait) try {
  if (!flags_() || flags_count_ < rx.count) {
    flags_count_ = std::max<size_t>(rx.count, 1);
    flags_ = cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, flags_count_);
    flags_resident_done_ = detail::fault_in(*rt_, {&flags_}, &flags_resident_first_);
  }
  ClassifyInputs in;
  in.depth = depth_;
  in.zmax_base = zmax_base_;
  in.zmax_chain = zmax_chain_;
  in.basis = basis;
  in.lookup = lookup;
  in.width = width_;
  in.height = height_;
  classify_done_ = rx.grid ? enqueue_esm_classify_grid(*rt_, options_, in, rx.d, visibility, flags_, wait)
                           : enqueue_esm_classify_points(*rt_, options_, rx.count, rx.row, in, rx.u, rx.v, rx.d,
                                                         visibility, flags_, wait);
  return classify_done_;
} catch (const cl::Error& e) {
  detail::throw_device_error("ClassifyStage::classify", e);
}

void ClassifyStage::add_times(StageTimes& t) const try {
  if (zmax_done_()) t.zmax = event_seconds(zmax_first_, zmax_done_);
  if (classify_done_()) t.classify = event_seconds(classify_done_);
  t.resident += detail::resident_seconds(resident_first_, resident_done_) +
                detail::resident_seconds(flags_resident_first_, flags_resident_done_);
} catch (const cl::Error& e) {
  detail::throw_device_error("ClassifyStage::add_times", e);
}

}  // namespace sf

// ESM failure classification (kernels/esm_classify.cl).
#include <cmath>
#include <string>

#include "cl_errors.hpp"
#include "method_build.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf {
namespace {

struct ClassifyParams {  // sf_classify_params
  cl_int mode;
  cl_int radius;
  cl_float offset;
  cl_float log_thresh;
};

cl::Kernel classify_kernel(Runtime& rt, const FilterOptions& opt, const char* name) {
  if (opt.method != "esm") throw InputError("FilterOptions::esm_classify.mode needs FilterOptions::method esm, got " + opt.method);
  const MethodDesc& m = find_method("esm");
  m.validate(opt);
  const std::string defines = "-cl-std=CL1.2 " + detail::method_lookup_build_options(m, opt);
  cl::Program p = rt.program({"common.clh", "storage.clh", m.header, "lookup.clh", "esm_classify.cl"},
                             defines);
  return cl::Kernel(p, name);
}

ClassifyParams params(const FilterOptions& opt) {
  ClassifyParams c{};
  c.mode = static_cast<cl_int>(opt.esm_classify.mode);
  c.radius = opt.blur.radius;
  c.offset = opt.esm_classify.zmax_offset;
  c.log_thresh = static_cast<float>(std::log1p(esm_threshold_eps(opt)));
  return c;
}

void set_or_null(cl::Kernel& k, cl_uint i, const cl::Buffer& b) {
  if (b())
    k.setArg(i, b);
  else
    k.setArg(i, sizeof(cl_mem), nullptr);
}

// Arguments 0..6 shared by both kernels.
void set_common(cl::Kernel& k, const ClassifyInputs& in) {
  k.setArg(0, in.basis);
  set_or_null(k, 1, in.lookup.chain);
  set_or_null(k, 2, in.lookup.sat);
  k.setArg(3, in.depth);
  set_or_null(k, 4, in.zmax_chain);
  k.setArg(5, in.width);
  k.setArg(6, in.height);
}

void check(const FilterOptions& opt, const ClassifyInputs& in) {
  if (opt.esm_classify.mode == EsmClassify::None) throw InputError("classification mode is none");
  if (opt.esm_classify.mode == EsmClassify::ZMax && !in.zmax_chain() && (in.width > 1 || in.height > 1))
    throw InputError("zmax classification needs the z-max pyramid");
}

}  // namespace

double esm_threshold_eps(const FilterOptions& opt) {
  if (opt.esm_classify.threshold_eps >= 0) return opt.esm_classify.threshold_eps;
  return std::exp(double(opt.esm.c) * opt.esm_classify.zmax_offset) * (1 + 1e-5) - 1;
}

cl::Event enqueue_esm_classify_points(Runtime& rt, const FilterOptions& opt, const ClassifyInputs& in,
                                      const cl::Buffer& u, const cl::Buffer& v, const cl::Buffer& d,
                                      const cl::Buffer& visibility, const cl::Buffer& flags,
                                      size_t count, const EventList* wait) try {
  check(opt, in);
  cl::Kernel k = classify_kernel(rt, opt, "sf_esm_classify_points");
  set_common(k, in);
  k.setArg(7, u);
  k.setArg(8, v);
  k.setArg(9, d);
  set_or_null(k, 10, in.lookup.footprint);
  k.setArg(11, visibility);
  k.setArg(12, flags);
  k.setArg(13, static_cast<int>(count));
  const ClassifyParams c = params(opt);
  k.setArg(14, sizeof c, &c);
  const auto P = find_method("esm").pack_params(opt);
  k.setArg(15, P.size(), P.data());
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(std::max<size_t>(count, 1)),
                                  cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_esm_classify_points", e);
}

cl::Event enqueue_esm_classify_grid(Runtime& rt, const FilterOptions& opt, const ClassifyInputs& in,
                                    const cl::Buffer& d, const cl::Buffer& visibility,
                                    const cl::Buffer& flags, const EventList* wait) try {
  check(opt, in);
  cl::Kernel k = classify_kernel(rt, opt, "sf_esm_classify_grid");
  set_common(k, in);
  k.setArg(7, d);
  k.setArg(8, visibility);
  k.setArg(9, flags);
  const ClassifyParams c = params(opt);
  k.setArg(10, sizeof c, &c);
  const auto P = find_method("esm").pack_params(opt);
  k.setArg(11, P.size(), P.data());
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(in.width, in.height), cl::NullRange,
                                  wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_esm_classify_grid", e);
}

}  // namespace sf

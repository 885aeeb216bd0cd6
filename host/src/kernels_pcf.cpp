// Host wrappers of kernels/pcf.cl (sm and pcf): one program for every radius and bias, the
// Gaussian weights travel by value in a kernel argument.
#include <algorithm>
#include <string>

#include "cl_errors.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/kernels.hpp"

namespace sf {
namespace {

struct PcfWeights {
  float w[kMaxBlurRadius + 1] = {};  // matches sf_pcf_weights (SF_PCF_MAX_RADIUS = 64)
};
static_assert(kMaxBlurRadius == 64, "kernels/pcf.cl assumes SF_PCF_MAX_RADIUS = kMaxBlurRadius");

struct PcfSetup {
  cl::Kernel kernel;
  int radius = 0;
  float bias = 0;
  PcfWeights weights;
};

PcfSetup pcf_setup(Runtime& rt, const FilterOptions& opt, const char* name, Lookup lookup = Lookup::Bilinear) {
  const MethodDesc& m = find_method(opt.method);
  if (!m.raw_depth) throw InputError("method " + opt.method + " does not read the depth map itself");
  m.validate(opt);
  PcfSetup s;
  // Footprint lookups reuse lookup.clh's level-of-detail rule (one float channel).
  const cl::Program p =
      lookup == Lookup::Bilinear
          ? rt.program({"common.clh", "pcf.cl"}, "-cl-std=CL1.2")
          : rt.program({"common.clh", "storage.clh", "lookup.clh", "pcf.cl"},
                       "-cl-std=CL1.2 -DSF_STORAGE=0 -DSF_CHANNELS=1 -DSF_LOOKUP=" +
                           std::to_string(static_cast<int>(lookup)));
  s.kernel = cl::Kernel(p, name);
  s.radius = opt.method == "sm" ? 0 : opt.blur.radius;
  s.bias = depth_bias(opt);
  const auto w = gaussian_weights(s.radius, opt.blur.sigma);
  std::copy(w.begin(), w.end(), s.weights.w);
  return s;
}

}  // namespace

cl::Event enqueue_pcf_points(Runtime& rt, const FilterOptions& opt, const cl::Buffer& depth,
                             int width, int height, const cl::Buffer& u, const cl::Buffer& v,
                             const cl::Buffer& d, const cl::Buffer& visibility, size_t count,
                             const EventList* wait, const cl::Buffer* footprint) try {
  // sm is the unfiltered test (methods.md): footprints do not apply to it (docs/lookups.md).
  const Lookup lookup = opt.method == "pcf" ? opt.lookup.kind : Lookup::Bilinear;
  PcfSetup s = lookup == Lookup::Bilinear ? pcf_setup(rt, opt, "sf_pcf_points")
                                          : pcf_setup(rt, opt, "sf_pcf_points_footprint", lookup);
  cl::Kernel& k = s.kernel;
  if (lookup != Lookup::Bilinear) {
    if (footprint && (*footprint)())
      k.setArg(11, *footprint);
    else
      k.setArg(11, sizeof(cl_mem), nullptr);
  }
  k.setArg(0, depth);
  k.setArg(1, width);
  k.setArg(2, height);
  k.setArg(3, u);
  k.setArg(4, v);
  k.setArg(5, d);
  k.setArg(6, visibility);
  k.setArg(7, static_cast<int>(count));
  k.setArg(8, s.bias);
  k.setArg(9, s.radius);
  k.setArg(10, sizeof(PcfWeights), &s.weights);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(count), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pcf_points", e);
}

cl::Event enqueue_pcf_grid(Runtime& rt, const FilterOptions& opt, const cl::Buffer& depth, int width,
                           int height, const cl::Buffer& d, const cl::Buffer& visibility,
                           const EventList* wait) try {
  PcfSetup s = pcf_setup(rt, opt, "sf_pcf_grid");
  cl::Kernel& k = s.kernel;
  k.setArg(0, depth);
  k.setArg(1, width);
  k.setArg(2, height);
  k.setArg(3, d);
  k.setArg(4, visibility);
  k.setArg(5, s.bias);
  k.setArg(6, s.radius);
  k.setArg(7, sizeof(PcfWeights), &s.weights);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(width, height), cl::NullRange, wait,
                                  &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pcf_grid", e);
}

}  // namespace sf

// Host wrappers of kernels/pcf.cl (sm and pcf): one program for every radius and bias, the
// Gaussian weights travel by value in a kernel argument.
#include <algorithm>
#include <string>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "plane_params.hpp"
#include "planned_scope.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/method_kernels.hpp"

namespace sf {
namespace {

static_assert(kMaxBlurRadius == SF_PCF_MAX_RADIUS, "the raw-depth tests take every prefilter radius");

struct PcfSetup {
  cl::Kernel kernel;
  int radius = 0;
  float bias = 0;
  sf_pcf_weights weights{};
  sf_plane_params plane{};
};

PcfSetup pcf_setup(Runtime& rt, const FilterOptions& opt, const char* name, Lookup lookup = Lookup::Bilinear,
                   int aniso = 1) {
  const MethodDesc& m = *opt.method;
  if (!m.raw_depth) throw InputError("method " + opt.method.name() + " does not read the depth map itself");
  detail::validate_unless_planned(m, opt);
  PcfSetup s;
  // Footprint lookups reuse lookup.clh's level-of-detail rule (one float channel).
  const cl::Program p = lookup == Lookup::Bilinear
                            ? rt.program({"common.clh", "receiver_plane.clh", "pcf.cl"}, detail::BuildOptions().str())
                            : rt.program({"common.clh", "storage.clh", "lookup.clh", "receiver_plane.clh", "pcf.cl"},
                                         detail::BuildOptions()
                                             .storage(Storage::F32)
                                             .define("SF_CHANNELS", 1)
                                             .lookup(lookup)
                                             .define_if(aniso > 1, "SF_ANISO", aniso)
                                             .str());
  s.kernel = cl::Kernel(p, name);
  s.radius = m.filtered ? opt.blur.radius : 0;
  s.bias = depth_bias(opt);
  const auto w = gaussian_weights(s.radius, opt.blur.sigma);
  std::copy(w.begin(), w.end(), s.weights.w);
  s.plane = detail::plane_params(opt.receiver_plane, 0);
  return s;
}

}  // namespace

cl::Event enqueue_pcf_points(Runtime& rt, const FilterOptions& opt, int width, int height, size_t count,
                             int receiver_row, const cl::Buffer& depth, const cl::Buffer& u, const cl::Buffer& v,
                             const cl::Buffer& d, const cl::Buffer& footprint, const cl::Buffer& jacobian,
                             const cl::Buffer& visibility, const EventList* wait) try {
  // sm is the unfiltered test (methods.md): footprints do not apply to it (docs/lookups.md).
  const Lookup lookup = opt.method->filtered ? opt.lookup.kind : Lookup::Bilinear;
  const int aniso = detail::anisotropy(lookup, jacobian, opt.lookup.max_anisotropy);
  PcfSetup s = lookup == Lookup::Bilinear ? pcf_setup(rt, opt, "sf_pcf_points")
                                          : pcf_setup(rt, opt, "sf_pcf_points_footprint", lookup, aniso);
  detail::KernelArgs args(s.kernel);
  args.buffer(depth)
      .value(width)
      .value(height)
      .buffer(u)
      .buffer(v)
      .buffer(d)
      .buffer(visibility)
      .value(static_cast<int>(count))
      .value(s.bias)
      .value(s.radius)
      .value(s.weights);
  if (lookup != Lookup::Bilinear) args.optional(aniso > 1 ? jacobian : footprint);
  s.plane.row = receiver_row;
  args.value(s.plane);
  cl::Kernel& k = s.kernel;
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(count), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pcf_points", e);
}

cl::Event enqueue_pcf_grid(Runtime& rt, const FilterOptions& opt, int width, int height, const cl::Buffer& depth,
                           const cl::Buffer& d, const cl::Buffer& visibility, const EventList* wait) try {
  PcfSetup s = pcf_setup(rt, opt, "sf_pcf_grid");
  cl::Kernel& k = s.kernel;
  detail::KernelArgs(k)
      .buffer(depth)
      .value(width)
      .value(height)
      .buffer(d)
      .buffer(visibility)
      .value(s.bias)
      .value(s.radius)
      .value(s.weights)
      .value(s.plane);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(width, height), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pcf_grid", e);
}

}  // namespace sf

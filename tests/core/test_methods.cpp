// Every basis method's transform and reconstruction kernels against the scalar reference, for
// every storage format the method accepts (tolerances stated per check).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/pipeline.hpp"
#include "test_methods_common.hpp"

namespace sf::test {
namespace {

// Float32 error of the kernel's basis value v against the exact one, per method:
//  esm   exp(c (z - 1/2)): argument rounded to half an ulp of c/2 -> relative 1e-6 + 1e-7 c.
//  vsm   z^2: 1 rounding -> relative 1.2e-7.
//  evsm  exp(c w) with c <= 42: the argument's rounding (2 roundings of |c w| <= 42, 5e-6) is the
//        relative error of e, doubled in e^2 -> relative 1.2e-5.
//  msm   z^k: up to 3 roundings, relative 4e-7; optimised (unorm16): sums of 4 terms with
//        coefficients up to 82 -> absolute 4 x 82 x 1.2e-7 ~ 4e-5.
//  csm   sin/cos((2k-1) pi z): float pi z is rounded (relative 6e-8, so 2e-7 k absolute in the
//        angle) and each angle-addition step adds ~2 ulp: the float recurrence on the CPU is off
//        by 4.6e-7 M at worst over 1e5 depths; tolerance 2e-6 + 6e-7 M.
double basis_tolerance(const MethodCase& mc, double v) {
  const bool unorm = mc.storage == Storage::Unorm16 || mc.storage == Storage::Unorm8;
  const double av = std::fabs(v);
  double f32;
  if (mc.method == "esm")
    f32 = (1e-6 + 1e-7 * 80) * av;
  else if (mc.method == "vsm")
    f32 = 1.2e-7 * av + 1e-12;
  else if (mc.method.name().rfind("evsm", 0) == 0)
    f32 = 1.2e-5 * av;
  else if (mc.method.name().rfind("msm", 0) == 0)
    f32 = unorm ? 4e-5 : 4e-7 * av + 1e-12;
  else
    f32 = 2e-6 + 6e-7 * mc.csm_order;
  // A value within f32 error of a rounding boundary may round either way: one storage step.
  return f32 + (mc.storage == Storage::F32 ? 0.0 : storage_step(v, mc.storage));
}

class MethodKernels : public ::testing::TestWithParam<MethodCase> {};

TEST_P(MethodKernels, TransformMatchesReference) {
  const MethodCase mc = GetParam();
  const FilterOptions opt = mc.options();
  const MethodDesc& m = *mc.method;
  const int ch = m.channels(opt);
  for (const HostImage& depth : stress_depths()) {
    cl::Buffer z = to_device(depth.data);
    const size_t n = depth.texels() * ch;
    cl::Buffer basis(runtime().context(), CL_MEM_READ_WRITE, n * storage_bytes(mc.storage));
    enqueue_transform(runtime(), m, opt, depth.width, depth.height, z, basis).wait();
    const auto got = read_stored(basis, n, mc.storage);
    const auto want = ref::transform(opt, depth);
    for (size_t i = 0; i < n; ++i) {
      const double w = ref::quantise(want.data[i], mc.storage);
      ASSERT_TRUE(std::isfinite(got[i])) << mc.label() << " value " << i;
      ASSERT_NEAR(got[i], w, basis_tolerance(mc, want.data[i]))
          << mc.label() << " channel " << i / depth.texels() << " z=" << depth.data[i % depth.texels()];
    }
  }
}

// The vector transform (transform.cl: sf_transformv) at every vector width, and the one-texel
// kernel (width 1), on a 37x29 map: 1073 texels, so the last work-item finishes a partial run of
// 1073 mod w texels with the scalar basis. Depths 0 and 1 sit in the tail. Same tolerances as
// above; the tail and the vector body must both match.
TEST_P(MethodKernels, TransformPartialTailEveryVectorWidth) {
  const MethodCase mc = GetParam();
  const MethodDesc& m = *mc.method;
  HostImage depth = random_depth(37, 29, 11);
  const size_t texels = depth.texels();
  depth.data[texels - 1] = 1.0f;
  depth.data[texels - 2] = 0.0f;
  depth.data[texels - 3] = 0.5f;
  cl::Buffer z = to_device(depth.data);
  for (int width : {1, 4, 8, 16}) {
    FilterOptions opt = mc.options();
    opt.schedule.transform_vector_width = width;
    const size_t n = texels * m.channels(opt);
    cl::Buffer basis(runtime().context(), CL_MEM_READ_WRITE, n * storage_bytes(mc.storage));
    enqueue_transform(runtime(), m, opt, depth.width, depth.height, z, basis).wait();
    const auto got = read_stored(basis, n, mc.storage);
    const auto want = ref::transform(opt, depth);
    for (size_t i = 0; i < n; ++i) {
      const double w = ref::quantise(want.data[i], mc.storage);
      ASSERT_TRUE(std::isfinite(got[i])) << mc.label() << " width " << width << " value " << i;
      ASSERT_NEAR(got[i], w, basis_tolerance(mc, want.data[i]))
          << mc.label() << " width " << width << " channel " << i / texels << " texel " << i % texels
          << " z=" << depth.data[i % texels];
    }
  }
}

// The reconstruction kernels (bilinear lookup + sf_visibility, points and grid) against the
// reference's lookup and visibility in double *on the same stored basis* read back from the
// device, so that only the float arithmetic of lookup and reconstruction differs. Bilinear mixes
// add ~3 ulp (relative 4e-7) to each looked-up value; how much that moves v depends on the
// method's conditioning (tolerance per method below, worst case over these maps).
double visibility_tolerance(const MethodCase& mc) {
  if (mc.method == "esm") return 2e-5 + 1e-7 * 80;  // log-space, see test_kernels.cpp
  // Chebyshev p = var / (var + t^2): dp <= dvar / (4 var) with dvar ~ 4e-7 m2 <= 4e-7 and
  // var >= vmin = 2e-5 (vsm) -> 5e-3; EVSM's relative floor keeps var >= (1e-4 c e)^2 against
  // dvar ~ 4e-7 e^2 -> 4e-7 / (4 (1e-4 c)^2) <= 6e-3 for c- = 5 (f16: floor 2e-3, c 5.54: less).
  if (mc.method == "vsm" || mc.method.name().rfind("evsm", 0) == 0) return 6e-3;
  // MSM reconstructs in double (msm.clh): on the same moments it matches the double reference to
  // rounding, then returns v in float: the Hankel solve amplifies double rounding by ~1/a^2 and
  // which side of a root a receiver falls can differ by that much (measured 1e-5 at unorm16's
  // near-singular z = 0 moments). Its inputs are not the same at bilinear points, though: the
  // float lookup rounds each moment (~2 ulp), and the solve amplifies that by ~1/a. Points are
  // therefore checked for backward error (msm_backward_ok); the 2e-5 applies to grid receivers.
  if (mc.method.name().rfind("msm", 0) == 0) return 2e-5;
  // CSM: f = 1/2 + 2 sum_k (...)/c_k with |terms| <= 1/c_k: 2M float roundings of order 1e-7
  // each, plus the recurrence of d (4e-7 k): 1e-6 + 1e-6 M, times scale.
  return (1e-6 + 1e-6 * mc.csm_order) * 2;
}

// The kernel's v is the exact v of moments within 4 float ulps of the looked-up ones: it lies in
// the range the reference gives over 32 random such perturbations, widened by 2e-5 (as grid).
bool msm_backward_ok(const ref::MethodRef& mr, std::vector<double> b, double d, double got) {
  double lo = mr.visibility(b.data(), d), hi = lo;
  std::mt19937 rng(unsigned(d * 1e6));
  std::uniform_real_distribution<double> r(-4.0, 4.0);
  const std::vector<double> b0 = b;
  for (int k = 0; k < 32; ++k) {
    for (size_t c = 0; c < b.size(); ++c) b[c] = b0[c] * (1 + r(rng) * std::ldexp(1.0, -24));
    const double v = mr.visibility(b.data(), d);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  return got >= lo - 2e-5 && got <= hi + 2e-5;
}

TEST_P(MethodKernels, ReconstructionMatchesReference) {
  const MethodCase mc = GetParam();
  const FilterOptions opt = mc.options();
  const MethodDesc& m = *mc.method;
  const ref::MethodRef mr = ref::method_ref(opt);
  const double tol = visibility_tolerance(mc);
  std::vector<HostImage> depths = stress_depths();
  for (const HostImage& depth : depths) {
    Pipeline pipe(runtime_ptr(), opt, depth.width, depth.height);
    cl::Buffer z = to_device(depth.data);
    pipe.prefilter(z).wait();
    const int ch = pipe.basis_shape().channels;
    ref::Planes stored(depth.width, depth.height, ch);
    const auto vals = read_stored(pipe.basis(), stored.data.size(), mc.storage);
    std::copy(vals.begin(), vals.end(), stored.data.begin());

    // Points: random (u, v, d) over the map plus the odd ones (outside, NaN, d out of [0,1]).
    std::mt19937 rng(depth.width);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> u, v, d;
    for (int i = 0; i < 400; ++i) {
      u.push_back(unit(rng));
      v.push_back(unit(rng));
      d.push_back(i % 7 == 0 ? depth.data[i % depth.texels()] : unit(rng));
    }
    for (float dd : {-0.5f, 0.0f, 1.0f, 1.5f, NAN}) {
      u.push_back(0.5f);
      v.push_back(0.5f);
      d.push_back(dd);
    }
    u.push_back(-0.1f);
    v.push_back(0.5f);
    d.push_back(0.5f);
    cl::Buffer ub = to_device(u), vb = to_device(v), db = to_device(d);
    cl::Buffer out(runtime().context(), CL_MEM_READ_WRITE, u.size() * sizeof(float));
    enqueue_reconstruct_points(runtime(), m, opt, depth.width, depth.height, u.size(), 0, pipe.basis(), nullptr, ub, vb,
                               db, out)
        .wait();
    const auto got = from_device(out, u.size());
    std::vector<double> b(ch);
    double worst = 0;
    for (size_t i = 0; i < u.size(); ++i) {
      ASSERT_TRUE(std::isfinite(got[i]) && got[i] >= 0.0f && got[i] <= 1.0f) << mc.label() << " " << got[i];
      double want = 1.0;
      if (std::isfinite(d[i]) && u[i] >= 0 && u[i] <= 1) {
        for (int c = 0; c < ch; ++c) b[c] = ref::bilinear(stored, c, u[i], v[i]);
        want = mr.visibility(b.data(), std::clamp(double(d[i]), 0.0, 1.0));
        if (mc.method.name().rfind("msm", 0) == 0 && msm_backward_ok(mr, b, std::clamp(double(d[i]), 0.0, 1.0), got[i]))
          want = got[i];
      }
      if (std::abs(got[i] - want) > tol && std::getenv("SF_TEST_VERBOSE")) {
        std::cerr << mc.label() << " point i=" << i << " u=" << u[i] << " v=" << v[i] << " d=" << d[i] << " got "
                  << got[i] << " want " << want << " b=";
        for (double x : b) std::cerr << x << " ";
        std::cerr << "\n";
      }
      worst = std::max(worst, std::abs(got[i] - want));
    }
    EXPECT_LE(worst, tol) << mc.label() << " points, map " << depth.width << "x" << depth.height;

    // Grid: one receiver per texel with its own depth nudged by a random amount.
    std::vector<float> dg(depth.texels());
    for (size_t i = 0; i < dg.size(); ++i) dg[i] = std::clamp(depth.data[i] + (unit(rng) - 0.5f) * 0.2f, 0.0f, 1.0f);
    cl::Buffer dgb = to_device(dg);
    cl::Buffer outg(runtime().context(), CL_MEM_READ_WRITE, dg.size() * sizeof(float));
    enqueue_reconstruct_grid(runtime(), m, opt, depth.width, depth.height, pipe.basis(), dgb, outg).wait();
    const auto gotg = from_device(outg, dg.size());
    worst = 0;
    for (size_t i = 0; i < dg.size(); ++i) {
      const int x = int(i % depth.width), y = int(i / depth.width);
      for (int c = 0; c < ch; ++c) b[c] = stored.at(c, x, y);
      const double e = std::abs(gotg[i] - mr.visibility(b.data(), dg[i]));
      if (e > worst && e > tol && std::getenv("SF_TEST_VERBOSE")) {
        std::cerr << mc.label() << " grid i=" << i << " z=" << depth.data[i] << " d=" << dg[i] << " got " << gotg[i]
                  << " want " << mr.visibility(b.data(), dg[i]) << " b=";
        for (double x : b) std::cerr << x << " ";
        std::cerr << "\n";
      }
      worst = std::max(worst, e);
    }
    EXPECT_LE(worst, tol) << mc.label() << " grid, map " << depth.width << "x" << depth.height;
  }
}

INSTANTIATE_TEST_SUITE_P(AllStorages, MethodKernels, ::testing::ValuesIn(basis_cases()),
                         [](const auto& info) { return info.param.label(); });

// sm and pcf against the brute-force reference (which with bias 0 is s_ref): weights are
// products of float32 Gaussian and bilinear weights (relative 3e-7 each), summed over at most
// (2R+2)^2 terms in float: absolute 1e-5 for R <= 4; the 0/1 tests themselves are exact because
// the kernel evaluates the same (z - d) + b sign in float as the reference does on float inputs
// (b = 0, or b exactly representable with |z - d| >> ulp).
class RawDepth : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(RawDepth, PointsAndGridMatchReference) {
  const auto [method, radius] = GetParam();
  FilterOptions opt;
  opt.method = method;
  opt.blur.radius = radius;
  for (float bias : {0.0f, 0.0625f}) {
    opt.depth_test.bias = bias;  // explicit
    for (const HostImage& depth : stress_depths()) {
      Receivers rx;
      std::mt19937 rng(depth.width + radius);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);
      rx.width = 300;
      rx.height = 1;
      for (int i = 0; i < rx.width; ++i) {
        rx.u.push_back(i == 0 ? -0.2f : unit(rng));
        rx.v.push_back(unit(rng));
        rx.d.push_back(i == 1 ? NAN : i % 5 == 0 ? depth.data[i % depth.texels()] : unit(rng));
      }
      const auto got = filter(runtime_ptr(), opt, depth, rx).visibility.data;
      const auto want = ref::filter(opt, depth, rx);
      for (size_t i = 0; i < want.size(); ++i)
        ASSERT_NEAR(got[i], want[i], 1e-5) << method << " R=" << radius << " bias=" << bias << " i=" << i;

      Receivers grid;
      grid.grid = true;
      grid.width = depth.width;
      grid.height = depth.height;
      grid.d = random_depth(depth.width, depth.height, 3).data;
      const auto gg = filter(runtime_ptr(), opt, depth, grid).visibility.data;
      const auto wg = ref::filter(opt, depth, grid);
      for (size_t i = 0; i < wg.size(); ++i) ASSERT_NEAR(gg[i], wg[i], 1e-5) << method << " grid " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Radii, RawDepth,
                         ::testing::Combine(::testing::Values("sm", "pcf"), ::testing::Values(0, 1, 4)));

// With bias 0, pcf is s_ref (methods.md sec. 2) on the same receivers, to double rounding.
TEST(RawDepth, PcfWithoutBiasIsSref) {
  const HostImage depth = random_depth(40, 30, 21);
  BlurOptions blur{3, 0.0f};
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const double u = unit(rng), v = unit(rng), d = unit(rng);
    ASSERT_NEAR(ref::pcf(depth, blur, u, v, d, 0.0), ref::s_ref(depth, blur, u, v, d), 1e-12);
  }
}

// A prefilter on the basis methods: the whole pipeline (transform, blur, lookup) in f32 against
// the reference on the device's own blurred basis, as above.
TEST(MethodKernels, BlurredPipelineMatchesReference) {
  const HostImage depth = random_depth(45, 38, 11, 0.2f, 0.8f);
  for (const char* name : {"vsm", "evsm4", "msm", "csm"}) {
    FilterOptions opt;
    opt.method = name;
    opt.blur.radius = 2;
    const MethodCase mc{name, Storage::F32, 8};
    Pipeline pipe(runtime_ptr(), opt, depth.width, depth.height);
    cl::Buffer z = to_device(depth.data);
    pipe.prefilter(z).wait();
    const int ch = pipe.basis_shape().channels;
    ref::Planes stored(depth.width, depth.height, ch);
    const auto vals = from_device(pipe.basis(), stored.data.size());
    std::copy(vals.begin(), vals.end(), stored.data.begin());
    // The device blur against the double blur of the device transform's output: relative 1e-5
    // (test_kernels.cpp, Blur) on positive planes; csm's signed planes: absolute 1e-5.
    cl::Buffer unblurred(runtime().context(), CL_MEM_READ_WRITE, stored.data.size() * 4);
    enqueue_transform(runtime(), pipe.method(), opt, depth.width, depth.height, z, unblurred).wait();
    ref::Planes raw(depth.width, depth.height, ch);
    const auto rv = from_device(unblurred, raw.data.size());
    std::copy(rv.begin(), rv.end(), raw.data.begin());
    const ref::Planes blurred = ref::blur(raw, 2, 0.0);
    for (size_t i = 0; i < vals.size(); ++i)
      ASSERT_NEAR(vals[i], blurred.data[i], 1e-5 * std::max(1.0, std::fabs(blurred.data[i]))) << name << " " << i;
    const ref::MethodRef mr = ref::method_ref(opt);
    Receivers grid;
    grid.grid = true;
    grid.width = depth.width;
    grid.height = depth.height;
    grid.d = random_depth(depth.width, depth.height, 9).data;
    const auto got = filter(runtime_ptr(), opt, depth, grid).visibility.data;
    std::vector<double> b(ch);
    for (size_t i = 0; i < got.size(); ++i) {
      for (int c = 0; c < ch; ++c) b[c] = stored.data[c * depth.texels() + i];
      ASSERT_NEAR(got[i], mr.visibility(b.data(), grid.d[i]), visibility_tolerance(mc)) << name << " " << i;
    }
  }
}

// Combinations that cannot work are refused with the limit named.
TEST(MethodLimits, RefusalsNameTheLimit) {
  auto refused = [](FilterOptions o, const std::string& needle) {
    try {
      o.method->validate(o);
      ADD_FAILURE() << o.method << " " << storage_name(o.storage) << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  FilterOptions o;
  o.method = "esm";
  o.storage = Storage::F16;
  o.esm.c = 80;
  refused(o, "float16 limit of 22");
  o.esm.c = 20;
  EXPECT_NO_THROW(sf::method("esm")->validate(o));
  o.storage = Storage::Unorm8;
  refused(o, "unorm");
  o.method = "evsm4";
  o.storage = Storage::Unorm16;
  refused(o, "f32 f16");
  o.method = "msm";
  o.storage = Storage::F16;
  refused(o, "unorm16");
  o.method = "vsm";
  o.storage = Storage::Unorm8;
  refused(o, "1/255");
  o.method = "sm";
  o.storage = Storage::F16;
  refused(o, "no basis");
  o = FilterOptions();
  o.method = "csm";
  o.csm.order = 33;
  refused(o, "1..32");
  o.csm.order = 0;
  refused(o, "1..32");
  o = FilterOptions();
  o.method = "vsm";
  o.vsm.lbr = 1.0f;
  refused(o, "[0, 1)");
  EXPECT_THROW(parse_storage("f64"), InputError);
  o = FilterOptions();
  o.schedule.transform_vector_width = 3;
  const cl::Buffer one = to_device(std::vector<float>(1, 0.5f));
  try {
    enqueue_transform(runtime(), *sf::method("esm"), o, 1, 1, one, one);
    ADD_FAILURE() << "transform vector width 3 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("1, 4, 8 or 16"), std::string::npos) << e.what();
  }
}

// EVSM exponents are clamped to the storage's limit (not refused): the packed parameters hold
// min(c, 42) in float32 and min(c, 5.54) in float16.
TEST(MethodLimits, EvsmExponentsClampToStorage) {
  FilterOptions o;
  o.method = "evsm4";
  o.evsm.pos = 80;
  o.evsm.neg = 60;
  auto params = [&] {
    const auto bytes = sf::method("evsm4")->pack_params(o);
    std::vector<float> p(bytes.size() / 4);
    std::memcpy(p.data(), bytes.data(), bytes.size());
    return p;
  };
  EXPECT_EQ(params()[0], 42.0f);
  EXPECT_EQ(params()[1], 42.0f);
  o.storage = Storage::F16;
  EXPECT_EQ(params()[0], 5.54f);
  EXPECT_EQ(params()[1], 5.54f);
  // And at the clamp the f16 basis stays finite: exp(2 * 5.54) = 65210 < 65504.
  const HostImage depth = stress_depths()[3];  // 0/1 checkerboard: both extremes
  cl::Buffer z = to_device(depth.data);
  cl::Buffer basis(runtime().context(), CL_MEM_READ_WRITE, depth.texels() * 4 * 2);
  enqueue_transform(runtime(), *sf::method("evsm4"), o, depth.width, depth.height, z, basis).wait();
  for (float v : read_stored(basis, depth.texels() * 4, Storage::F16)) ASSERT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace sf::test

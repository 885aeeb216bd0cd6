// Numerical stability at the extremes: every method through the whole pipeline
// (sf::filter) on degenerate inputs. Every output must be finite and in [0,1] (strict: one bad
// value fails); the worst |v - s_ref| (s_ref with the same weights, ref::s_ref) is printed as a
// "NUMERICS|" line that docs/numerics.md tabulates, and bounded where the math makes the answer
// exact (stated per test).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "lookups.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/sat.hpp"

namespace sf::test {
namespace {

// Planar receivers (one per texel) at depth d(x, y).
Receivers grid_receivers(int w, int h, const std::function<float(int, int)>& d) {
  Receivers r;
  r.width = w;
  r.height = h;
  r.grid = true;
  r.d.resize(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) r.d[size_t(y) * w + x] = d(x, y);
  return r;
}

struct Outcome {
  double worst = 0;  // max |v - s_ref|
  size_t bad = 0;    // non-finite or outside [0,1]
  std::string first_bad;
};

// Runs `o` on (depth, rx), checks every value, returns the worst error against s_ref with the
// configuration's weights (sm: no prefilter) and prints the NUMERICS line.
Outcome run_case(const std::string& name, const FilterOptions& o, const HostImage& depth, const Receivers& rx) {
  const FilterResult r = filter(runtime_ptr(), o, depth, rx);
  BlurOptions blur = o.blur;
  if (o.method == "sm") blur = BlurOptions{};
  // sm and pcf against their reference (s_ref of the receivers' planes, ref::filter), the
  // others against s_ref of d.
  const std::vector<double> want =
      o.method->raw_depth ? ref::filter(o, depth, rx) : ref::s_ref(depth, blur, Lookup::Bilinear, rx);
  Outcome out;
  for (size_t i = 0; i < want.size(); ++i) {
    const float v = r.visibility.data[i];
    if (!std::isfinite(v) || v < 0.0f || v > 1.0f) {
      if (!out.bad++) out.first_bad = "receiver " + std::to_string(i) + " = " + std::to_string(v);
      continue;
    }
    out.worst = std::max(out.worst, std::abs(double(v) - want[i]));
  }
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::printf("NUMERICS| %s | %s | %.3g | %s.%s\n", name.c_str(), o.method.name().c_str(), out.bad ? NAN : out.worst,
              info->test_suite_name(), info->name());
  return out;
}

FilterOptions method_options(const std::string& m, int radius = 0) {
  FilterOptions o;
  o.method = m;
  o.blur.radius = m == "sm" ? 0 : radius;
  return o;
}

std::vector<std::string> all_methods() {
  std::vector<std::string> out;
  for (const auto& m : methods()) out.push_back(m.name);
  return out;
}

#define EXPECT_SANE(outcome) EXPECT_EQ((outcome).bad, 0u) << (outcome).first_bad

// Depth exactly 0 and exactly 1, and a constant 0.5: the filtered basis of a constant map is the
// basis of that constant, so every method sees a single depth. Receivers sit on the surface
// (d = z, lit: s_ref = 1), in front (lit) and behind by >= 0.25 (s_ref = 0). Bound 0.05: the
// failure band of these methods at 0.25 behind a single occluder depth (esm exp(-80*0.25),
// vsm/evsm at their minimum variance, csm ringing at M = 8 <= 0.03 by measurement, msm bias).
TEST(Numerics, ConstantMapsAtZeroHalfAndOne) {
  for (float z : {0.0f, 0.5f, 1.0f})
    for (const auto& m : all_methods()) {
      const HostImage depth(16, 12, 1, z);
      const Receivers rx = grid_receivers(16, 12, [z](int x, int y) {
        const int k = (x + 2 * y) % 3;  // on, in front, behind
        if (k == 0) return z;
        if (k == 1) return std::max(0.0f, z - 0.25f);
        return std::min(1.0f, z + 0.25f);
      });
      const Outcome r = run_case("constant z=" + std::to_string(z).substr(0, 3), method_options(m, 2), depth, rx);
      EXPECT_SANE(r) << m << " z=" << z;
      if (m != "csm") {
        EXPECT_LE(r.worst, 0.05) << m << " z=" << z;
      }
    }
}

// A 0/1 checkerboard with receivers at 0.5 (s_ref = the filtered fraction of 1s, about 1/2):
// the hardest two-depth case (maximal variance). Only sanity is asserted for the approximations;
// pcf must equal s_ref to float rounding (1e-5).
TEST(Numerics, CheckerboardZeroOne) {
  HostImage depth(32, 32, 1);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) depth.at(x, y) = float((x + y) % 2);
  const Receivers rx = grid_receivers(32, 32, [](int, int) { return 0.5f; });
  for (const auto& m : all_methods()) {
    const Outcome r = run_case("0/1 checkerboard, d=0.5, R=3", method_options(m, 3), depth, rx);
    EXPECT_SANE(r) << m;
    if (m == "pcf" || m == "sm") {
      EXPECT_LE(r.worst, 1e-5) << m;
    }
  }
}

// Neighbouring depths 1e-6 apart (below float32 resolution near 0.5: ulp 6e-8, so they are
// distinct): receivers exactly on the nearer depth must be lit by s_ref. Bound 0.02: esm at
// c = 80 gives exp(-80 * 1e-6) = 1 - 8e-5; vsm/evsm have variance ~1e-12 below v_min: p = 1.
TEST(Numerics, DepthsOneMillionthApart) {
  HostImage depth(24, 24, 1);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) depth.at(x, y) = 0.5f + ((x ^ y) & 1 ? 1e-6f : 0.0f);
  const Receivers rx = grid_receivers(24, 24, [](int, int) { return 0.5f; });
  for (const auto& m : all_methods()) {
    const Outcome r = run_case("depths 1e-6 apart, d on the nearer", method_options(m, 1), depth, rx);
    EXPECT_SANE(r) << m;
    if (m != "csm") {
      EXPECT_LE(r.worst, 0.02) << m;
    }
  }
}

// ESM exponents: 1, 40, 80, 88 (where the unshifted exp(cz) loses z < 0.01 to denormals), 120
// and 174 (the centred storage's float32 limit); 175 must be refused with an InputError naming
// the limit. Random map, receivers at the surface + 0.01 .. - 0.01.
TEST(Numerics, EsmExponents) {
  const HostImage depth = random_depth(40, 40, 3, 0.0f, 1.0f);
  const Receivers rx = grid_receivers(
      40, 40, [&](int x, int y) { return std::clamp(depth.at(x, y) + 0.01f * float((x % 3) - 1), 0.0f, 1.0f); });
  for (float c : {1.0f, 40.0f, 80.0f, 88.0f, 120.0f, 174.0f}) {
    FilterOptions o = method_options("esm", 2);
    o.esm.c = c;
    const Outcome r = run_case("esm c=" + std::to_string(int(c)), o, depth, rx);
    EXPECT_SANE(r) << "c=" << c;
  }
  FilterOptions o = method_options("esm", 2);
  o.esm.c = 175.0f;
  EXPECT_THROW(filter(runtime_ptr(), o, depth, rx), InputError);
  std::printf("NUMERICS| esm c=175 | esm | refused (InputError) | Numerics.EsmExponents\n");
}

// EVSM at the storage limits: c+ = 42 (float32: exp(2*42) = 3e36 < 3.4e38), beyond it (100,
// clamped by the registry), and float16 at its limit c+ = 5.54 (exp(11.08) = 65e3 < 65504).
TEST(Numerics, EvsmAtStorageLimits) {
  const HostImage depth = random_depth(32, 32, 5, 0.0f, 1.0f);
  const Receivers rx = grid_receivers(32, 32, [&](int x, int y) { return depth.at(x, y); });
  for (const char* m : {"evsm2", "evsm4"}) {
    for (float pos : {42.0f, 100.0f}) {
      FilterOptions o = method_options(m, 2);
      o.evsm.pos = pos;
      o.evsm.neg = pos;
      EXPECT_SANE(run_case("evsm f32 c+=c-=" + std::to_string(int(pos)), o, depth, rx)) << m;
    }
    FilterOptions o = method_options(m, 0);
    o.storage = Storage::F16;
    o.evsm.pos = 5.54f;
    o.evsm.neg = 5.54f;
    EXPECT_SANE(run_case("evsm f16 c+=c-=5.54, R=0", o, depth, rx)) << m;
  }
}

// CSM orders 1..32 in unorm8 (values mapped from [-1,1] to 8 bits, no prefilter: the basis
// quantisation alone). Bound: none beyond sanity for the approximation (M = 1 is a sine); the
// errors are tabulated.
TEST(Numerics, CsmOrdersInUnorm8) {
  const HostImage depth = random_depth(32, 32, 9, 0.2f, 0.8f);
  const Receivers rx = grid_receivers(32, 32, [&](int x, int y) { return depth.at(x, y) + 0.1f * ((x + y) % 2); });
  for (int M : {1, 2, 4, 16, 32}) {
    FilterOptions o = method_options("csm", 0);
    o.storage = Storage::Unorm8;
    o.csm.order = M;
    EXPECT_SANE(run_case("csm unorm8 M=" + std::to_string(M), o, depth, rx)) << "M=" << M;
  }
}

// VSM near depth 1: z in [0.999, 1], E[z^2] - E[z]^2 cancels catastrophically in float32 (ulp of
// z^2 near 1 is 6e-8 and the true variance is ~1e-7). The minimum variance must keep the bound
// finite: receivers on the surface (d = z) must stay lit within 0.1 (Chebyshev with v_min 2e-5).
TEST(Numerics, VsmCancellationNearOne) {
  const HostImage depth = random_depth(32, 32, 11, 0.999f, 1.0f);
  const Receivers on = grid_receivers(32, 32, [&](int x, int y) { return depth.at(x, y); });
  for (const char* m : {"vsm", "evsm2", "evsm4", "msm"}) {
    const Outcome r = run_case("z in [0.999,1], d = z", method_options(m, 2), depth, on);
    EXPECT_SANE(r) << m;
  }
  const Receivers behind = grid_receivers(32, 32, [](int, int) { return 1.0f; });
  EXPECT_SANE(run_case("z in [0.999,1], d = 1", method_options("vsm", 2), depth, behind));
}

// Tiny images: 1x1, 1xN and Nx1 for every method, and a blur radius far larger than the image
// (R = 15 on 1x1 and 5x3): clamp-to-edge makes the filtered map the image's own (weighted)
// values. Receivers above and below the depths.
TEST(Numerics, TinyImagesAndHugeRadius) {
  struct Sz {
    int w, h, r;
  };
  for (Sz s : {Sz{1, 1, 1}, Sz{1, 37, 3}, Sz{37, 1, 3}, Sz{1, 1, 15}, Sz{5, 3, 15}}) {
    const HostImage depth = random_depth(s.w, s.h, 13 + s.w, 0.2f, 0.8f);
    const Receivers rx = grid_receivers(s.w, s.h, [&](int x, int y) { return (x + y) % 2 ? 0.1f : 0.9f; });
    for (const auto& m : all_methods()) {
      const std::string name = std::to_string(s.w) + "x" + std::to_string(s.h) + " R=" + std::to_string(s.r);
      const Outcome r = run_case(name, method_options(m, s.r), depth, rx);
      EXPECT_SANE(r) << m << " " << name;
      if (m == "pcf" || m == "sm") {
        EXPECT_LE(r.worst, 1e-5) << m << " " << name;
      }
    }
  }
}

// SAT at 4096x4096 (16.7M texels, prefix sums up to 8.4e6 for values in [0,1]): the float-float
// table must keep box means exact to 1e-5. Checked on boxes of 1, 64x64 and the whole image
// against double sums of the same texels.
TEST(Numerics, Sat4096) {
  const int W = 4096, H = 4096;
  std::vector<float> host(size_t(W) * H);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (auto& v : host) v = dist(rng);
  const ImageShape shape{W, H, 1, 4};
  const SatLayout L = sat_layout(shape);
  cl::Buffer src = to_device(host);
  cl::Buffer table(runtime().context(), CL_MEM_READ_WRITE, L.table_floats * sizeof(float));
  cl::Buffer bands(runtime().context(), CL_MEM_READ_WRITE, L.band_floats * sizeof(float));
  enqueue_sat(runtime(), Storage::F32, {}, {}, shape, src, table, bands).wait();
  const auto t = from_device(table, L.table_floats);
  auto S = [&](int x, int y) { return double(t[L.at(0, false, x, y)]) + double(t[L.at(0, true, x, y)]); };
  struct Box {
    int x0, y0, x1, y1;
  };
  double worst = 0;
  bool finite = true;
  for (Box b : {Box{0, 0, W, H}, Box{4095, 4095, 4096, 4096}, Box{2000, 3000, 2064, 3064}, Box{0, 4032, 64, 4096},
                Box{4032, 0, 4096, 64}, Box{1, 1, 2, 2}}) {
    double want = 0;
    for (int y = b.y0; y < b.y1; ++y)
      for (int x = b.x0; x < b.x1; ++x) want += host[size_t(y) * W + x];
    const double area = double(b.x1 - b.x0) * (b.y1 - b.y0);
    const double got = S(b.x1, b.y1) - S(b.x0, b.y1) - S(b.x1, b.y0) + S(b.x0, b.y0);
    finite = finite && std::isfinite(got);
    worst = std::max(worst, std::abs(got - want) / area);
  }
  std::printf("NUMERICS| SAT 4096x4096, box means | (lookup) | %.3g | Numerics.Sat4096\n", worst);
  EXPECT_TRUE(finite);
  EXPECT_LE(worst, 1e-5);
}

}  // namespace
}  // namespace sf::test

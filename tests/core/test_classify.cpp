// ESM failure classification (kernels/esm_classify.cl, Annen 2008 ch. 7.3).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>

#include "image_io.hpp"
#include "lookups.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// Depth layers: a far floor with a slope, two blocks in front, noise; receivers at random
// positions and footprints, with depths near the local surface (so texels behind and in front
// of them both occur in most supports).
struct Case {
  HostImage depth;
  Receivers rx;
};

Case layered_case(unsigned seed) {
  Case c;
  c.depth = HostImage(96, 80, 1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 96; ++x) {
      float z = 0.7f + 0.002f * x + noise(rng);
      if (x > 20 && x < 50 && y > 10 && y < 40) z = 0.35f + noise(rng);
      if (x > 60 && x < 90 && y > 30 && y < 70) z = 0.5f + 0.003f * y;
      c.depth.at(x, y) = z;
    }
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), lf(0.0f, 5.0f), dd(-0.05f, 0.05f);
  for (int i = 0; i < 2000; ++i) {
    const float u = unit(rng), v = unit(rng);
    const int x = std::min(int(u * 96), 95), y = std::min(int(v * 80), 79);
    c.rx.u.push_back(u);
    c.rx.v.push_back(v);
    c.rx.d.push_back(std::clamp(c.depth.at(x, y) + dd(rng), 0.0f, 1.0f));
    c.rx.f.push_back(i % 5 == 0 ? 1.0f : std::exp2(lf(rng)));
  }
  c.rx.width = 2000;
  c.rx.height = 1;
  c.rx.has_footprint = true;
  return c;
}

FilterOptions classify_options(Lookup kind, int radius, EsmClassify mode) {
  FilterOptions o;
  o.method = "esm";
  o.esm.c = 80.0f;
  o.blur.radius = radius;
  o.lookup.kind = kind;
  o.esm_classify.mode = mode;
  return o;
}

class Classify : public ::testing::TestWithParam<std::tuple<Lookup, int>> {};

// zmax is conservative: a receiver whose support (every texel with a non-zero composite weight,
// ref::lookup_taps) holds a texel with z > d + offset is flagged. Exact comparison in float32,
// as the kernel does it. threshold (automatic eps) flags a subset of zmax. And it is tight: the
// bilinear and trilinear lookups read exactly their support's texels widened by R from the
// dilated pyramid (esm_classify.cl), so they flag exactly those receivers (these receivers have
// no zero bilinear weight, which would make the read box larger than the support); the SAT's
// box reads the 2x2 blocks of the level that covers it, a superset (here within 12%).
TEST_P(Classify, ZMaxFlagsEveryTexelBehindAndThresholdIsASubset) {
  const auto [kind, radius] = GetParam();
  const Case c = layered_case(3 + radius);
  auto zopt = classify_options(kind, radius, EsmClassify::ZMax);
  auto topt = classify_options(kind, radius, EsmClassify::Threshold);
  // The summed-area table keeps box means relative to its largest entries: with ESM values
  // spanning exp(c * 0.56) over this map it holds c <= 24.9 (docs/numerics.md, "Lookup limits"),
  // and the pipeline refuses more (c = 80 had left box means of dark regions with errors far
  // above 1e-5 relative, and the subset property needed c <= ~25).
  if (kind == Lookup::Sat) zopt.esm.c = topt.esm.c = 20.0f;
  const auto z = filter(runtime_ptr(), zopt, c.depth, c.rx);
  const auto t = filter(runtime_ptr(), topt, c.depth, c.rx);
  ASSERT_TRUE(z.classified && t.classified);
  size_t must = 0, zflag = 0, tflag = 0;
  for (size_t i = 0; i < c.rx.u.size(); ++i) {
    const float d = c.rx.d[i];
    bool behind = false;
    for (const auto& tap :
         ref::lookup_taps(c.depth.width, c.depth.height, zopt.blur, kind, c.rx.u[i], c.rx.v[i], c.rx.f[i]))
      behind |= c.depth.at(tap.x, tap.y) > d + zopt.esm_classify.zmax_offset;
    must += behind;
    zflag += z.flags.data[i] > 0;
    tflag += t.flags.data[i] > 0;
    if (behind) {
      ASSERT_EQ(z.flags.data[i], 1.0f) << "receiver " << i << " f=" << c.rx.f[i];
    }
    if (t.flags.data[i] > 0) {
      ASSERT_EQ(z.flags.data[i], 1.0f) << "threshold-only flag, receiver " << i;
    }
  }
  EXPECT_GT(must, 100u) << "the case must exercise the test";
  if (kind == Lookup::Sat)
    EXPECT_LE(zflag, must * 1.12);
  else
    EXPECT_EQ(zflag, must);
  EXPECT_EQ(zflag, z.flagged);
  EXPECT_LT(tflag, zflag);
  std::printf("[ classify lookup %d R=%d ] support behind %zu, zmax %zu, threshold %zu of %zu\n", int(kind), radius,
              must, zflag, tflag, c.rx.u.size());
}

INSTANTIATE_TEST_SUITE_P(KindsAndRadii, Classify,
                         ::testing::Combine(::testing::Values(Lookup::Bilinear, Lookup::Mips, Lookup::Sat),
                                            ::testing::Values(0, 2)));

// The vector kernel (sf_esm_classify_points_vec: zmax with bilinear or trilinear lookups, the
// flag test and the fall-back as SF_RX_VEC lanes) against the one-receiver kernel (vector width
// 1) on a receiver image: a floor seen in rows, planes from neighbours, background lanes and a
// row width that splits vectors. Flags exactly equal; visibility within 2e-6 (the plane's and
// the exponential's float rounding, vector against scalar code).
TEST(Classify, VectorKernelMatchesTheOneReceiverKernel) {
  const Case c = layered_case(5);
  Receivers rx;
  rx.width = 61, rx.height = 37;  // 61: rows start mid-vector
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> jitter(-0.004f, 0.004f);
  for (int y = 0; y < rx.height; ++y)
    for (int x = 0; x < rx.width; ++x) {
      const float u = 0.03f + 0.94f * (x + 0.5f) / rx.width, v = 0.03f + 0.94f * (y + 0.5f) / rx.height;
      const int tx = std::min(int(u * 96), 95), ty = std::min(int(v * 80), 79);
      const bool background = (x * 7 + y * 3) % 23 == 0;
      rx.u.push_back(u);
      rx.v.push_back(v);
      rx.d.push_back(background ? NAN : std::clamp(c.depth.at(tx, ty) + 0.01f + jitter(rng), 0.0f, 1.0f));
      rx.f.push_back(1.0f + 3.0f * float(y) / rx.height);
    }
  rx.has_footprint = true;
  // The same receivers with footprints up to 2^8 texels: lookups and z-max reads on every level
  // of the 96x80 map's chain, down to those 1 texel wide (read lane by lane, not as pairs).
  Receivers wide = rx;
  for (size_t i = 0; i < wide.f.size(); ++i) wide.f[i] = std::exp2(8.0f * float(i % 61) / 60.0f);
  for (const Receivers* r : {&rx, &wide})
    for (EsmClassify mode : {EsmClassify::ZMax, EsmClassify::Threshold})
      for (Lookup kind : {Lookup::Bilinear, Lookup::Mips}) {
        SCOPED_TRACE(std::string(mode == EsmClassify::ZMax ? "zmax" : "threshold") +
                     (kind == Lookup::Mips ? " mips" : " bilinear") + (r == &wide ? " wide" : ""));
        auto opt = classify_options(kind, 2, mode);
        const auto vec = filter(runtime_ptr(), opt, c.depth, *r);
        opt.schedule.reconstruct_vector_width = 1;
        const auto one = filter(runtime_ptr(), opt, c.depth, *r);
        // threshold flags a subset of zmax's receivers (docs/lookups.md): its own, lower bound
        ASSERT_GT(vec.flagged, r->u.size() / (mode == EsmClassify::ZMax ? 20 : 50)) << "the case must flag receivers";
        if (r == &rx) {
          ASSERT_LT(vec.flagged, r->u.size() * 9 / 10);
        }
        for (size_t i = 0; i < r->u.size(); ++i) {
          ASSERT_EQ(vec.flags.data[i], one.flags.data[i]) << "receiver " << i;
          ASSERT_NEAR(vec.visibility.data[i], one.visibility.data[i], 2e-6) << "receiver " << i;
        }
      }
}

TEST(Classify, GridReceiversAreClassifiedToo) {
  const Case c = layered_case(9);
  Receivers grid;
  grid.grid = true;
  grid.width = c.depth.width;
  grid.height = c.depth.height;
  grid.d = c.depth.data;
  for (auto& d : grid.d) d -= 0.02f;  // in front of its own texel: flagged only by neighbours
  const auto opt = classify_options(Lookup::Bilinear, 1, EsmClassify::ZMax);
  const auto r = filter(runtime_ptr(), opt, c.depth, grid);
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x) {
      bool behind = false;
      for (int b = -1; b <= 1; ++b)
        for (int a = -1; a <= 1; ++a)
          behind |= c.depth.at(std::clamp(x + a, 0, grid.width - 1), std::clamp(y + b, 0, grid.height - 1)) >
                    grid.d[size_t(y) * grid.width + x] + opt.esm_classify.zmax_offset;
      ASSERT_EQ(r.flags.at(x, y) > 0, behind) << x << "," << y;  // exact: the support is the 3x3
    }
}

// Annen 2008 fig. 7.2 (a): a receiver at d = 0.5 between a blocker (z = 0.3) and a surface behind it
// (z = 0.9) in its prefilter support. exp(c (z - d)) of the far texels overflows the filtered
// sum: ESM returns 1 where s_ref is partial. The fall-back (2x2 PCF of the ESM test on the raw
// depth) returns the bilinear test: exp(-c 0.2) = 1e-7 for blockers, 1 behind.
TEST(Classify, FallbackRemovesTheEsmOvershoot) {
  HostImage depth(64, 16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 64; ++x) depth.at(x, y) = x < 32 ? 0.3f : 0.9f;
  Receivers rx;
  for (int i = 0; i < 41; ++i) {  // across the edge, between texel centres too
    rx.u.push_back((22.0f + 0.5f * i) / 64.0f);
    rx.v.push_back(0.5f);
    rx.d.push_back(0.5f);
  }
  rx.width = int(rx.u.size());
  rx.height = 1;
  FilterOptions opt = classify_options(Lookup::Bilinear, 4, EsmClassify::None);
  const auto plain = filter(runtime_ptr(), opt, depth, rx);
  opt.esm_classify.mode = EsmClassify::ZMax;
  const auto fixed = filter(runtime_ptr(), opt, depth, rx);
  double worst_plain = 0, worst_fixed = 0;
  for (size_t i = 0; i < rx.u.size(); ++i) {
    const double sref = ref::s_ref(depth, opt.blur, Lookup::Bilinear, rx.u[i], rx.v[i], 0.5, 1.0);
    const double bilinear_test = ref::s_ref(depth, {0, 0.0f}, Lookup::Bilinear, rx.u[i], rx.v[i], 0.5, 1.0);
    worst_plain = std::max(worst_plain, plain.visibility.data[i] - sref);
    if (fixed.flags.data[i] > 0) {
      // Bilinear weights times 1e-7 blocker terms, float32: 1e-5.
      ASSERT_NEAR(fixed.visibility.data[i], bilinear_test, 1e-5) << "receiver " << i;
    }
    worst_fixed = std::max(worst_fixed, fixed.visibility.data[i] - std::max(sref, bilinear_test));
  }
  EXPECT_GT(worst_plain, 0.4) << "the case must show the overshoot";
  EXPECT_LT(worst_fixed, 1e-5);
}

}  // namespace
}  // namespace sf::test

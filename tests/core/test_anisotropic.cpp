// Anisotropic footprints (footprint.hpp; kernels/lookup.clh "Anisotropic footprints"): the probe
// split, the lookups against the double reference's, every basis method and pcf through the
// pipeline against their twins, and the isotropic cases they must leave exactly as they were.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <cstdio>
#include <random>

#include "device_lookup.hpp"
#include "lookups.hpp"
#include "receiver_plane.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/footprint.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/sat_precision.hpp"

namespace sf::test {
namespace {

// ---- The probe split.

TEST(FootprintProbes, AnIsotropicJacobianIsOneProbeOfItsFootprint) {
  for (const float f : {0.25f, 1.0f, 3.0f, 17.5f, 300.0f}) {
    const FootprintProbes p = footprint_probes(f, 0.0f, 0.0f, f, 8);
    EXPECT_EQ(p.n, 1) << f;
    EXPECT_EQ(p.f, f);
    EXPECT_EQ(p.fx, f);
    EXPECT_EQ(p.fy, f);
    // Rotated by 30 degrees: still one probe of footprint f (the box grows to its bounding square).
    const float c = std::cos(0.5236f) * f, s = std::sin(0.5236f) * f;
    const FootprintProbes r = footprint_probes(c, s, -s, c, 8);
    EXPECT_EQ(r.n, 1) << f;
    EXPECT_NEAR(r.f, f, 1e-6 * f);
  }
}

TEST(FootprintProbes, AGrazingFootprintIsCutAlongItsMajorAxis) {
  // 8 texels along u, 1 along v: eight 1 x 1 probes one texel apart, which tile the 8 x 1 box.
  FootprintProbes p = footprint_probes(8.0f, 0.0f, 0.0f, 1.0f, 8);
  EXPECT_EQ(p.n, 8);
  EXPECT_EQ(p.du, 1.0f);
  EXPECT_EQ(p.dv, 0.0f);
  EXPECT_EQ(p.f, 1.0f);
  EXPECT_EQ(p.fx, 1.0f);
  EXPECT_EQ(p.fy, 1.0f);
  EXPECT_EQ(p.offset(0), -3.5f);
  EXPECT_EQ(p.offset(7), 3.5f);
  // The major axis along the image's y (column jy), 12 x 2 texels: n = 6, 2 x 2 probes.
  p = footprint_probes(0.0f, 2.0f, 12.0f, 0.0f, 8);
  EXPECT_EQ(p.n, 6);
  EXPECT_EQ(p.du, 2.0f);
  EXPECT_EQ(p.f, 2.0f);
  EXPECT_EQ(p.fx, 2.0f);
  EXPECT_EQ(p.fy, 2.0f);
  // Capped at max_anisotropy: 4 probes of 2 texels along the 8.
  p = footprint_probes(8.0f, 0.0f, 0.0f, 1.0f, 4);
  EXPECT_EQ(p.n, 4);
  EXPECT_EQ(p.f, 2.0f);
  EXPECT_EQ(p.fx, 2.0f);
  // A footprint under a texel across: the ratio is against one texel (a thinner one is no finer).
  p = footprint_probes(6.0f, 0.0f, 0.0f, 0.1f, 16);
  EXPECT_EQ(p.n, 6);
  // Diagonal 8:1 (45 degrees): 8 probes along the diagonal, each 1 texel of footprint; the box
  // of each part bounds it (1/sqrt 2 along each axis from the step, as much from the minor column).
  const float a = 8.0f / std::sqrt(2.0f), b = 1.0f / std::sqrt(2.0f);
  p = footprint_probes(a, a, -b, b, 8);
  EXPECT_EQ(p.n, 8);
  EXPECT_NEAR(p.f, 1.0f, 1e-6);
  EXPECT_NEAR(p.du, b, 1e-6);
  EXPECT_NEAR(p.fx, 2 * b, 1e-6);
  EXPECT_NEAR(p.fy, 2 * b, 1e-6);
}

TEST(FootprintProbes, DegenerateJacobiansReadAsFootprintOne) {
  const float nan = std::nanf(""), inf = INFINITY;
  for (const auto& j : {std::array<float, 4>{nan, 0, 0, 1}, {1, inf, 0, 1}, {0, 0, 0, 0}}) {
    const FootprintProbes p = footprint_probes(j[0], j[1], j[2], j[3], 8);
    EXPECT_EQ(p.n, 1);
    EXPECT_TRUE(std::isfinite(p.f) && std::isfinite(p.fx) && std::isfinite(p.fy) && std::isfinite(p.du));
    EXPECT_LE(p.f, 1.0f);
  }
  // A line (det 0) of 1e30 texels: capped, finite, max_anisotropy probes.
  const FootprintProbes p = footprint_probes(1e30f, 0.0f, 1e30f, 0.0f, 16);
  EXPECT_EQ(p.n, 16);
  EXPECT_TRUE(std::isfinite(p.f) && std::isfinite(p.fx) && std::isfinite(p.du));
}

// ---- Receivers with Jacobians.

// n receivers (one row): coordinates over the map and a little past it, Jacobians of every
// orientation with ratios 1 .. 20 and major sides 0.5 .. 2^7 texels, a few isotropic ones.
Receivers jacobian_receivers(int n, unsigned seed, float dlo, float dhi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-0.02f, 1.02f), angle(0.0f, 6.2831853f), lg(-1.0f, 7.0f),
      ratio(1.0f, 20.0f), depth(dlo, dhi);
  Receivers rx;
  rx.width = n;
  rx.height = 1;
  rx.has_jacobian = true;
  for (int i = 0; i < n; ++i) {
    rx.u.push_back(std::clamp(coord(rng), 0.0f, 1.0f));
    rx.v.push_back(std::clamp(coord(rng), 0.0f, 1.0f));
    rx.d.push_back(depth(rng));
    const float major = std::exp2(lg(rng)), minor = i % 9 == 0 ? major : major / ratio(rng), t = angle(rng);
    // Columns: the major axis along t, the minor across it, in either column order.
    const float mu = major * std::cos(t), mv = major * std::sin(t), ou = -minor * std::sin(t), ov = minor * std::cos(t);
    const bool swap = i % 2 == 1;
    rx.dudx.push_back(swap ? ou : mu);
    rx.dvdx.push_back(swap ? ov : mv);
    rx.dudy.push_back(swap ? mu : ou);
    rx.dvdy.push_back(swap ? mv : ov);
  }
  footprint_from_jacobian(rx);
  return rx;
}

// Device lookups (lookup_values.cl) of a planar image at Jacobian receivers: out[c][i].
std::vector<std::vector<float>> aniso_lookup(const ref::Planes& img, Lookup kind, const Receivers& rx, int max_aniso) {
  LookupBuffers lk;
  lk.kind = kind;
  lk.footprint = to_device(rx.f);
  std::vector<float> planes;
  jacobian_planes(rx, planes);
  lk.jacobian = to_device(planes);
  lk.max_anisotropy = max_aniso;
  return device_lookup(img, lk, rx.u, rx.v);
}

// Values in [0.05, 1]; each probe is a lookup of Lookups.MatchTheReference (2e-6), the probes'
// coordinates are the reference's float ones, and their mean adds n float roundings: 3e-6.
class AnisotropicLookups : public ::testing::TestWithParam<std::tuple<Lookup, int>> {};

TEST_P(AnisotropicLookups, MatchTheReference) {
  const auto [kind, max_aniso] = GetParam();
  ref::Planes img(97, 61, 2);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> dist(0.05f, 1.0f);
  for (auto& v : img.data) v = dist(rng);
  const Receivers rx = jacobian_receivers(600, 11, 0.0f, 1.0f);
  const auto got = aniso_lookup(img, kind, rx, max_aniso);
  const ref::LookupRef lookup(img, kind);
  int probes = 0;
  for (size_t i = 0; i < rx.count(); ++i) {
    const FootprintProbes p = ref::probes_at(rx, i, max_aniso);
    probes = std::max(probes, p.n);
    for (int c = 0; c < img.channels; ++c)
      ASSERT_NEAR(got[size_t(c)][i], lookup.value(c, rx.u[i], rx.v[i], p), 3e-6)
          << "channel " << c << " receiver " << i << " n=" << p.n;
  }
  EXPECT_EQ(probes, max_aniso);  // the receivers reach the cap
}

INSTANTIATE_TEST_SUITE_P(KindsAndCaps, AnisotropicLookups,
                         ::testing::Combine(::testing::Values(Lookup::Mips, Lookup::Sat), ::testing::Values(4, 16)));

// A depth map with a step (a blocker over half of a slope) so that the filtered tests vary.
HostImage step_depth() {
  HostImage depth = random_depth(90, 70, 3, 0.35f, 0.6f);
  for (int y = 0; y < 70; ++y)
    for (int x = 0; x < 90; ++x)
      if ((x - 45) * (x - 45) + (y - 30) * (y - 30) < 400) depth.at(x, y) = 0.15f;
  return depth;
}

// Every basis method through the pipeline (the vector reconstruction, 211 receivers: a partial
// last vector), mips and sat, against ref::filter with the same probes. The methods'
// reconstructions amplify the lookups' float error by their own conditioning (test_methods.cpp):
// the anisotropic run must match its twin within what the isotropic run of the same receivers
// does, widened for the n-probe means, and the two runs must differ (the probes are read).
TEST(AnisotropicMethods, EveryBasisMethodMatchesItsTwin) {
  const HostImage depth = step_depth();
  const Receivers rx = jacobian_receivers(211, 7, 0.2f, 0.8f);
  for (const MethodDesc& m : methods()) {
    if (m.raw_depth) continue;
    for (const Lookup kind : {Lookup::Mips, Lookup::Sat}) {
      FilterOptions opt;
      opt.method = m.name;
      opt.lookup.kind = kind;
      opt.esm_classify.mode = EsmClassify::None;  // the reference has no classification stage
      if (m.name == "esm") opt.esm.c = 20.0f;     // c (zmax - zmin) within the sat table (test_lookup.cpp)
      if (kind == Lookup::Sat &&
          !sat_refusal(opt, SatMap{depth_range(depth), depth.width, depth.height, runtime().info().fp64}).empty())
        continue;
      double err[2] = {0, 0}, moved = 0;
      std::vector<float> iso;
      for (const int aniso : {1, 8}) {
        opt.lookup.max_anisotropy = aniso;
        const auto got = filter(runtime_ptr(), opt, depth, rx).visibility.data;
        const auto want = ref::filter(opt, depth, rx);
        for (size_t i = 0; i < rx.count(); ++i) {
          ASSERT_TRUE(std::isfinite(got[i])) << m.name << " receiver " << i;
          err[aniso > 1] = std::max(err[aniso > 1], std::abs(got[i] - want[i]));
        }
        if (aniso == 1)
          iso = got;
        else
          for (size_t i = 0; i < rx.count(); ++i) moved = std::max(moved, double(std::abs(got[i] - iso[i])));
      }
      std::printf("[ %s %s ] max |kernel - twin|: isotropic %.2g, anisotropic %.2g; max |aniso - iso| %.2g\n",
                  m.name.c_str(), kind == Lookup::Mips ? "mips" : "sat", err[0], err[1], moved);
      EXPECT_LE(err[1], std::max(4 * err[0], 2e-5)) << m.name;
      EXPECT_GT(moved, 0.05) << m.name;
    }
  }
}

// Receivers whose Jacobian is diag(f, f) read exactly what receivers of footprint f read, and
// max_anisotropy 1 ignores any Jacobian: every lookup, pcf among them, bit for bit.
TEST(AnisotropicMethods, IsotropicJacobiansAndCapOneAreTheIsotropicLookup) {
  const HostImage depth = step_depth();
  Receivers square = jacobian_receivers(203, 3, 0.2f, 0.8f);
  Receivers plain = square;
  plain.has_jacobian = false;
  for (size_t i = 0; i < square.count(); ++i) {
    square.dudx[i] = square.dvdy[i] = square.f[i];
    square.dvdx[i] = square.dudy[i] = 0.0f;
  }
  for (const char* name : {"esm", "msm", "pcf"})
    for (const Lookup kind : {Lookup::Mips, Lookup::Sat}) {
      FilterOptions opt;
      opt.method = name;
      opt.lookup.kind = kind;
      opt.esm.c = 20.0f;  // within the sat table on this map (test_lookup.cpp)
      const auto want = filter(runtime_ptr(), opt, depth, plain).visibility.data;
      EXPECT_EQ(filter(runtime_ptr(), opt, depth, square).visibility.data, want) << name;
      opt.lookup.max_anisotropy = 1;
      const Receivers grazing = jacobian_receivers(203, 3, 0.2f, 0.8f);
      Receivers grazing_plain = grazing;
      grazing_plain.has_jacobian = false;
      EXPECT_EQ(filter(runtime_ptr(), opt, depth, grazing).visibility.data,
                filter(runtime_ptr(), opt, depth, grazing_plain).visibility.data)
          << name;
    }
}

// pcf (kernels/pcf.cl, SF_ANISO) is the mean of its probes' filtered tests, each s_ref under the
// probe's composite weights against the receiver's own plane (ref::lookup_taps of the probes):
// float32 weights over up to a few 10^4 tests, as PcfFootprints: tolerance 1e-5.
TEST(AnisotropicMethods, PcfIsTheMeanOfItsProbesTests) {
  const HostImage depth = step_depth();
  const Receivers rx = jacobian_receivers(150, 5, 0.1f, 0.7f);
  for (const Lookup kind : {Lookup::Mips, Lookup::Sat})
    for (const int radius : {0, 2}) {
      FilterOptions opt;
      opt.method = "pcf";
      opt.lookup.kind = kind;
      opt.blur.radius = radius;
      opt.depth_test.bias = 1e-3f;  // off exact ties (test_lookup.cpp)
      const auto got = filter(runtime_ptr(), opt, depth, rx).visibility.data;
      const auto twin = ref::filter(opt, depth, rx);
      size_t partial = 0;
      for (size_t i = 0; i < rx.count(); ++i) {
        const ref::Plane plane = ref::receiver_plane(depth, rx, i, opt.receiver_plane);
        const double s = ref::s_ref(depth, opt.blur, kind, rx.u[i], rx.v[i], plane, ref::probes_at(rx, i, 8),
                                    plane.bias(depth_bias(opt), opt.receiver_plane.slope_bias));
        ASSERT_NEAR(twin[i], s, 1e-12) << i;
        ASSERT_NEAR(got[i], s, 1e-5) << "receiver " << i << " n=" << ref::probes_at(rx, i, 8).n << " kind " << int(kind)
                                     << " R " << radius << " u " << rx.u[i] << " v " << rx.v[i] << " du "
                                     << ref::probes_at(rx, i, 8).du << " dv " << ref::probes_at(rx, i, 8).dv;
        partial += s > 1e-3 && s < 1 - 1e-3;
      }
      EXPECT_GT(partial, rx.count() / 10);
    }
}

}  // namespace
}  // namespace sf::test

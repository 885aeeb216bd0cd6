// Footprint lookups (lookup.clh: trilinear over the mip chain, box via the SAT) against the
// scalar reference, and against s_ref with the lookup's composite weights.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "device_lookup.hpp"
#include "image_io.hpp"
#include "lookups.hpp"
#include "receiver_plane.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf::test {
namespace {

struct Rx {
  std::vector<float> u, v, f;
};

// Random receivers, some past the edges of [0,1] (clamp-to-edge), footprints 0.5 .. 2^8 texels
// (beyond the top level for small maps), exact powers of two and 1.
Rx random_rx(int n, unsigned seed) {
  Rx r;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(0.0f, 1.0f), lf(-1.0f, 8.0f);
  for (int i = 0; i < n; ++i) {
    r.u.push_back(coord(rng));
    r.v.push_back(coord(rng));
    r.f.push_back(i % 7 == 0 ? 1.0f : i % 11 == 0 ? float(1 << (i % 6)) : std::exp2(lf(rng)));
  }
  return r;
}

// n random_rx receivers with footprints (one row) and depths uniform in [dlo, dhi).
Receivers random_receivers(int n, unsigned seed, unsigned depth_seed, float dlo, float dhi) {
  const Rx r = random_rx(n, seed);
  Receivers rx;
  rx.width = n;
  rx.height = 1;
  rx.u = r.u;
  rx.v = r.v;
  rx.f = r.f;
  rx.has_footprint = true;
  std::mt19937 rng(depth_seed);
  std::uniform_real_distribution<float> dd(dlo, dhi);
  for (int i = 0; i < n; ++i) rx.d.push_back(dd(rng));
  return rx;
}

// Device lookups of `img` (planar, N channels) at the receivers: out[c][i].
std::vector<std::vector<float>> device_lookup(const ref::Planes& img, Lookup kind, const Rx& rx) {
  LookupBuffers lk;
  lk.kind = kind;
  lk.footprint = to_device(rx.f);
  return test::device_lookup(img, lk, rx.u, rx.v);
}

class Lookups : public ::testing::TestWithParam<std::tuple<Lookup, int, int, int>> {};

// Values in [0.05, 1]: the trilinear lookup is two bilinear lookups (float weights, ~1e-7) of
// levels with 1e-6 relative error and a float mix; the box is within 2.5e-7 (test_sat.cpp).
// The LOD comes from float32 log2 on both sides: tolerance 2e-6.
TEST_P(Lookups, MatchTheReference) {
  const auto [kind, w, h, channels] = GetParam();
  ref::Planes img(w, h, channels);
  std::mt19937 rng(w * 3 + h);
  std::uniform_real_distribution<float> dist(0.05f, 1.0f);
  for (auto& v : img.data) v = dist(rng);
  const Rx rx = random_rx(400, w + h);
  const auto got = device_lookup(img, kind, rx);
  const ref::LookupRef lookup(img, kind);
  for (int c = 0; c < channels; ++c)
    for (size_t i = 0; i < rx.u.size(); ++i)
      ASSERT_NEAR(got[c][i], lookup.value(c, rx.u[i], rx.v[i], rx.f[i]), 2e-6)
          << "channel " << c << " receiver " << i << " f=" << rx.f[i];
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, Lookups,
    ::testing::Values(std::make_tuple(Lookup::Mips, 1, 1, 1), std::make_tuple(Lookup::Mips, 37, 21, 2),
                      std::make_tuple(Lookup::Mips, 300, 131, 1), std::make_tuple(Lookup::Sat, 1, 1, 1),
                      std::make_tuple(Lookup::Sat, 37, 21, 3), std::make_tuple(Lookup::Sat, 300, 131, 1),
                      std::make_tuple(Lookup::Bilinear, 37, 21, 2)));

// A storage per plane (the reference of a basis whose planes are stored in different widths):
// one storage for every plane is the one-storage lookup exactly; unorm8 on plane 0 alone rounds
// plane 0's mip levels to 1/255 steps (within half a step of float32's, and not all equal to
// them) and leaves plane 1 as float32's.
TEST(Lookups, AStoragePerPlaneRoundsEachPlaneAsStored) {
  ref::Planes img(64, 48, 2);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dist(0.0, 1.0);
  for (auto& v : img.data) v = dist(rng);
  const Rx rx = random_rx(300, 11);
  const ref::LookupRef one(img, Lookup::Mips, Storage::Unorm16);
  const ref::LookupRef each(img, Lookup::Mips, std::vector<Storage>{Storage::Unorm16, Storage::Unorm16});
  const ref::LookupRef f32(img, Lookup::Mips, Storage::F32);
  const ref::LookupRef mixed(img, Lookup::Mips, std::vector<Storage>{Storage::Unorm8, Storage::F32});
  size_t moved = 0;
  for (size_t i = 0; i < rx.u.size(); ++i) {
    const double u = rx.u[i], v = rx.v[i], f = rx.f[i] + 2.0;  // f >= 2: reads level 1 and up
    for (int c = 0; c < 2; ++c) EXPECT_EQ(each.value(c, u, v, f), one.value(c, u, v, f));
    EXPECT_EQ(mixed.value(1, u, v, f), f32.value(1, u, v, f));
    const double diff = std::abs(mixed.value(0, u, v, f) - f32.value(0, u, v, f));
    EXPECT_LE(diff, 0.5 / 255.0 + 1e-7);
    moved += diff > 1e-6;
  }
  EXPECT_GT(moved, rx.u.size() / 2);
  EXPECT_THROW(ref::LookupRef(img, Lookup::Mips, std::vector<Storage>{Storage::F32}), std::invalid_argument);
}

class StepBasis : public ::testing::TestWithParam<std::tuple<Lookup, int>> {};

// A prefiltered method with a step basis B = H(z - d) for one fixed d (what pcf weights): its
// lookup (prefilter R, then trilinear or box) equals s_ref with the same composite weights,
// which the reference builds independently (lookup_taps: bilinear weights per level pushed down
// the pyramid, box coverage, then the Gaussian). Float32 sums of weights: tolerance 3e-6.
TEST_P(StepBasis, LookupsReproduceSRef) {
  const auto [kind, radius] = GetParam();
  HostImage depth = random_depth(67, 45, 21, 0.0f, 1.0f);
  for (int y = 10; y < 30; ++y)  // structure: a block in front
    for (int x = 20; x < 50; ++x) depth.at(x, y) = 0.1f;
  const double d = 0.45;
  std::vector<float> step(depth.texels());
  for (size_t i = 0; i < step.size(); ++i) step[i] = depth.data[i] >= d ? 1.0f : 0.0f;
  // Prefilter on the device (the library's blur), then the lookup.
  const ImageShape shape{depth.width, depth.height, 1, 4};
  cl::Buffer src = to_device(step);
  cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  enqueue_blur(runtime(), {radius, 0.0f}, {}, Storage::F32, shape, src, tmp, src).wait();
  ref::Planes blurred(depth.width, depth.height, 1);
  const auto b = from_device(src, step.size());
  for (size_t i = 0; i < b.size(); ++i) blurred.data[i] = b[i];
  const Rx rx = random_rx(300, 77 + radius);
  const auto got = device_lookup(blurred, kind, rx);
  for (size_t i = 0; i < rx.u.size(); ++i) {
    const double want = ref::s_ref(depth, {radius, 0.0f}, kind, rx.u[i], rx.v[i], d, rx.f[i]);
    ASSERT_NEAR(got[0][i], want, 3e-6) << "receiver " << i << " f=" << rx.f[i];
  }
}

INSTANTIATE_TEST_SUITE_P(KindsAndRadii, StepBasis,
                         ::testing::Combine(::testing::Values(Lookup::Mips, Lookup::Sat, Lookup::Bilinear),
                                            ::testing::Values(0, 2)));

// The composite weights are a partition of unity and cover what the lookup reads.
TEST(StepBasis, CompositeWeightsSumToOne) {
  for (Lookup kind : {Lookup::Bilinear, Lookup::Mips, Lookup::Sat})
    for (double f : {1.0, 2.5, 17.0, 300.0}) {
      double sum = 0;
      for (const auto& t : ref::lookup_taps(53, 29, {3, 0.0f}, kind, 0.31, 0.77, f)) sum += t.w;
      EXPECT_NEAR(sum, 1.0, 1e-12) << "kind " << int(kind) << " f " << f;
    }
}

// ESM through the pipeline with footprints (points mode) against the double reference with the
// same lookup, as test_kernels.cpp's EsmPipeline: tolerance 2e-5 + 1e-7 c.
class EsmLookupPipeline : public ::testing::TestWithParam<std::tuple<Lookup, int>> {};

TEST_P(EsmLookupPipeline, MatchesReference) {
  const auto [kind, radius] = GetParam();
  FilterOptions opt;
  // c (zmax - zmin) = 12 over depths 0.1 .. 0.7: within the 14.7 the table holds on this map
  // (docs/numerics.md, "Lookup limits"; the pipeline refuses more).
  opt.esm.c = 20.0f;
  opt.blur.radius = radius;
  opt.lookup.kind = kind;
  // The kernels alone: the reference has no classification stage (esm classifies by default).
  opt.esm_classify.mode = EsmClassify::None;
  HostImage depth = random_depth(70, 51, 3, 0.3f, 0.7f);
  for (int y = 10; y < 25; ++y)
    for (int x = 5; x < 40; ++x) depth.at(x, y) = 0.1f;
  const Receivers rx = random_receivers(500, 9, 4, 0.2f, 0.9f);
  const auto got = filter(runtime_ptr(), opt, depth, rx);
  const auto want = ref::filter(opt, depth, rx);
  // The box lookup subtracts table entries of the whole map's magnitude: float-float keeps about
  // 2^-44 of S_total, so a box mean is good to ~2^-44 S_total / area (docs/lookups.md, "sat and
  // ESM"), which v = bar(B') exp(c (1/2 - d)) scales up. Here the map spans exp(12): the
  // darkest boxes keep ~30 bits of the ~48. The tolerance adds that conditioning term (4 corners).
  double s_total = 0;
  for (float z : depth.data) s_total += std::exp(double(opt.esm.c) * (double(z) - 0.5));
  for (size_t i = 0; i < want.size(); ++i) {
    double tol = 2e-5 + 1e-7 * opt.esm.c;
    if (kind == Lookup::Sat) {
      const double side = std::max(1.0, double(rx.f[i]));
      tol += 4 * std::ldexp(s_total, -44) / (side * side) * std::exp(opt.esm.c * (0.5 - double(rx.d[i])));
    }
    ASSERT_NEAR(got.visibility.data[i], want[i], tol) << "receiver " << i << " f=" << rx.f[i];
  }
}

INSTANTIATE_TEST_SUITE_P(KindsAndRadii, EsmLookupPipeline,
                         ::testing::Combine(::testing::Values(Lookup::Mips, Lookup::Sat), ::testing::Values(0, 2)));

// pcf with footprints (kernels/pcf.cl, sf_pcf_points_footprint) is s_ref under the lookup's
// composite weights (lookup_taps: level bilinear pushed down, box coverage, then the Gaussian),
// on the bundled scenes' camera receivers (every 61st: floor footprints of tens of texels, edges
// of the map) and on random receivers of an odd-sized map (odd edges of the pyramid, footprints
// past the top level). Float32 weights summed over up to a few 10^4 tests: tolerance 1e-5. With
// the receiver plane on (the default) against s_ref of the same planes and the same bias (the
// constant plus the plane's slope-scaled term), and off against s_ref of d.
class PcfFootprints : public ::testing::TestWithParam<std::tuple<Lookup, int>> {};

void expect_pcf_is_sref(const FilterOptions& opt, const HostImage& depth, const Receivers& rx,
                        const std::string& what) {
  const auto got = filter(runtime_ptr(), opt, depth, rx).visibility.data;
  // The reference pipeline's pcf is s_ref(kind) too (checked where it is cheap).
  const auto want = rx.count() <= 500 ? ref::filter(opt, depth, rx) : std::vector<double>();
  double worst = 0;
  size_t partial = 0;
  for (size_t i = 0; i < rx.count(); ++i) {
    const ref::Plane plane = ref::receiver_plane(depth, rx, i, opt.receiver_plane);
    const double s = ref::s_ref(depth, opt.blur, opt.lookup.kind, rx.u[i], rx.v[i], plane, ref::footprint_at(rx, i),
                                plane.bias(depth_bias(opt), opt.receiver_plane.slope_bias));
    if (!want.empty()) {
      ASSERT_NEAR(want[i], s, 1e-12) << what << " reference " << i;
    }
    ASSERT_NEAR(got[i], s, 1e-5) << what << " receiver " << i << " f=" << rx.f[i];
    worst = std::max(worst, std::abs(got[i] - s));
    partial += s > 1e-3 && s < 1 - 1e-3;
  }
  // Penumbrae (0 < s_ref < 1) are where the weights matter: the receivers must contain some
  // (with the receiver plane the lit floors are no longer partial: spheres 28 of 1560 at R = 0).
  EXPECT_GT(partial, rx.count() / 100) << what;
  std::printf("[ pcf %s ] %zu receivers, %zu partial, max |pcf - s_ref| = %.2g\n", what.c_str(), rx.count(), partial,
              worst);
}

TEST_P(PcfFootprints, EqualsSRefWithTheSameWeights) {
  const auto [kind, radius] = GetParam();
  FilterOptions opt;
  opt.method = "pcf";
  opt.blur.radius = radius;
  opt.lookup.kind = kind;
  opt.depth_test.bias = 0.0f;
  for (const bool plane : {true, false}) {
    opt.receiver_plane.enabled = plane;
    // A lit receiver's plane from the depth map's slope is the map itself: a bias keeps the
    // tests off exact ties, where float and double may round either way.
    opt.depth_test.bias = plane ? 1e-3f : 0.0f;
    const std::string mode = plane ? " plane" : " flat";
    for (const std::string scene : {"spheres", "fence"}) {
      const HostImage depth = io::load_depth_map(data_path(scene + "/shadowmap.exr"), {});
      const Receivers all = io::load_receiver_image(data_path(scene + "/receivers.exr"));
      Receivers rx;
      rx.has_footprint = all.has_footprint;
      for (size_t i = 0; i < all.count(); i += 61) {
        if (!std::isfinite(all.d[i])) continue;
        rx.u.push_back(all.u[i]);
        rx.v.push_back(all.v[i]);
        rx.d.push_back(all.d[i]);
        rx.f.push_back(all.has_footprint ? all.f[i] : 1.0f);
      }
      rx.width = int(rx.u.size());
      rx.height = 1;
      ASSERT_TRUE(rx.has_footprint) << scene;
      expect_pcf_is_sref(opt, depth, rx,
                         scene + mode + " kind " + std::to_string(int(kind)) + " R " + std::to_string(radius));
    }
    HostImage depth = random_depth(67, 45, 21, 0.0f, 1.0f);
    for (int y = 10; y < 30; ++y)
      for (int x = 20; x < 50; ++x) depth.at(x, y) = 0.1f;
    const Receivers rx = random_receivers(400, 31 + radius, 5, 0.05f, 0.95f);
    expect_pcf_is_sref(opt, depth, rx,
                       "67x45" + mode + " kind " + std::to_string(int(kind)) + " R " + std::to_string(radius));
  }
}

INSTANTIATE_TEST_SUITE_P(KindsAndRadii, PcfFootprints,
                         ::testing::Combine(::testing::Values(Lookup::Bilinear, Lookup::Mips, Lookup::Sat),
                                            ::testing::Values(0, 2)));

// sm is the unfiltered test: a footprint lookup does not change it (docs/lookups.md).
TEST(PcfFootprints, SmIgnoresFootprints) {
  FilterOptions opt;
  opt.method = "sm";
  opt.depth_test.bias = 0.0f;
  const HostImage depth = random_depth(40, 30, 8, 0.0f, 1.0f);
  const Receivers rx = random_receivers(200, 3, 6, 0.0f, 1.0f);
  const auto plain = filter(runtime_ptr(), opt, depth, rx).visibility.data;
  opt.lookup.kind = Lookup::Mips;
  const auto mips = filter(runtime_ptr(), opt, depth, rx).visibility.data;
  for (size_t i = 0; i < plain.size(); ++i) ASSERT_EQ(plain[i], mips[i]) << "receiver " << i;
}

}  // namespace
}  // namespace sf::test

// Summed-area tables (kernels/sat.cl) and box lookups against the scalar reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lookups.hpp"
#include "sf_test_env.hpp"
#include "test_methods_common.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf::test {
namespace {

struct DeviceSat {
  cl::Buffer table;
  SatLayout layout;
};

// `builds` times into one table with one scratch (the later builds must not depend on what the
// earlier ones left there).
DeviceSat device_sat(const cl::Buffer& src, const ImageShape& shape, Storage storage = Storage::F32,
                     const SatBuild& build = {}, int builds = 1) {
  DeviceSat s;
  s.layout = sat_layout(shape);
  s.table = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, s.layout.table_floats * sizeof(float));
  cl::Buffer bands(runtime().context(), CL_MEM_READ_WRITE, s.layout.band_floats * sizeof(float));
  for (int i = 0; i < builds; ++i) enqueue_sat(runtime(), storage, build, {}, shape, src, s.table, bands).wait();
  return s;
}

// Every entry hi + lo of a device table (sat.cl layout) against the double table: double sums
// split into hi + lo (2^-47 relative), tolerance 1e-11 |S| + 1e-12.
void expect_table(const std::vector<float>& got, const SatLayout& L, const ref::Planes& want,
                  const std::string& label) {
  const int W = want.width - 1, H = want.height - 1;
  ASSERT_EQ(got.size(), L.table_floats);
  for (int c = 0; c < want.channels; ++c)
    for (int y = 0; y <= H; ++y)
      for (int x = 0; x <= W; ++x) {
        const double v = double(got[L.at(c, false, x, y)]) + double(got[L.at(c, true, x, y)]);
        const double w = want.at(c, x, y);
        ASSERT_NEAR(v, w, 1e-11 * w + 1e-12) << label << " channel " << c << " at " << x << "," << y;
      }
}

struct Size {
  int w, h, channels;
};
// Both accumulators (sat_accum.clh): double where the device has it (PoCL does), and the
// float-float fallback for devices without cl_khr_fp64; every schedule (each built twice on one
// scratch).
class Sat : public ::testing::TestWithParam<std::tuple<Size, SatAccumulator, SatSchedule>> {};

// A table of random texels in [0, 1) built (twice on one scratch) as `build` says, every entry
// hi + lo against the double table. Every partial sum (row totals, column sums, the band
// carries) is double, stored as hi + lo (2^-47), or float-float (about 2^-44 relative per
// addition): tolerance 1e-11 |S| + 1e-12 (a plain float32 prefix anywhere would be off by ~6e-8
// of a row's sum). Returns the layout.
SatLayout expect_random_table(const Size& s, const SatBuild& build, const std::string& label) {
  ref::Planes in(s.w, s.h, s.channels);
  std::mt19937 rng(s.w * 31 + s.h);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  std::vector<float> host(in.data.size());
  for (size_t i = 0; i < host.size(); ++i) in.data[i] = host[i] = dist(rng);
  const DeviceSat d = device_sat(to_device(host), {s.w, s.h, s.channels, 4}, Storage::F32, build, 2);
  expect_table(from_device(d.table, d.layout.table_floats), d.layout, ref::sat_table(in), label);
  return d.layout;
}

TEST_P(Sat, TableMatchesTheReference) {
  const auto [s, accumulator, schedule] = GetParam();
  SatBuild build;
  build.accumulator = accumulator;
  build.schedule = schedule;
  const SatLayout L =
      expect_random_table(s, build, accumulator == SatAccumulator::FloatFloat ? "f32 float-float" : "f32");
  if (s.h >= 32 && schedule == SatSchedule::Chained) {
    EXPECT_GT(L.chain_bands, 2) << "the chain's bands take carries from each other";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, Sat,
    ::testing::Combine(::testing::Values(Size{1, 1, 1}, Size{1, 40, 1}, Size{40, 1, 1}, Size{5, 3, 2}, Size{16, 16, 1},
                                         Size{17, 33, 1}, Size{100, 37, 3}, Size{257, 300, 1}, Size{640, 1000, 1}),
                       ::testing::Values(SatAccumulator::Auto, SatAccumulator::FloatFloat),
                       ::testing::Values(SatSchedule::PerChannel, SatSchedule::Chained, SatSchedule::TwoLaunch)));

// The chained build's look-back when the bands above have not published: every band sums all
// the rows above it (the path a band takes when the one above it was preempted), and with no
// polling at all (whatever each band finds published). Both accumulators, several channels.
class SatChain : public ::testing::TestWithParam<std::tuple<Size, SatAccumulator, bool>> {};

TEST_P(SatChain, LookBackSumsWhatIsNotPublished) {
  const auto [s, accumulator, sum_all] = GetParam();
  SatBuild build;
  build.accumulator = accumulator;
  build.schedule = SatSchedule::Chained;
  build.chain_polls = 0;
  build.chain_sum_all = sum_all;
  EXPECT_GE(expect_random_table(s, build, sum_all ? "every band sums the rows above" : "no polling").chain_bands, 4);
}

INSTANTIATE_TEST_SUITE_P(Sizes, SatChain,
                         ::testing::Combine(::testing::Values(Size{257, 300, 1}, Size{100, 37, 3}, Size{640, 1000, 1}),
                                            ::testing::Values(SatAccumulator::Auto, SatAccumulator::FloatFloat),
                                            ::testing::Bool()));

// Every entry of a 4096x4096 table against a long double (64-bit mantissa) table of the same
// floats. sat.cl sums in double (worst case (x + y + band_rows + bands) 2^-53 of S for
// non-negative texels, < 2^-39.8 S here) and splits each sum into hi + lo (2^-47 |S|):
// tolerance 1e-12 |S|; docs/lookups.md quotes the measured maximum.
// The float-float fallback: about 2^-44 of S per addition, measured below 1e-13 (same bound).
void expect_large_table_exact(SatAccumulator accumulator, SatSchedule schedule = SatSchedule::Auto) {
  const int n = 4096;
  std::vector<float> host(size_t(n) * n);
  std::mt19937 rng(4096);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) host[size_t(y) * n + x] = 0.5f * dist(rng) + 0.25f * float(x + y) / n;
  SatBuild build;
  build.accumulator = accumulator;
  build.schedule = schedule;
  const DeviceSat d = device_sat(to_device(host), {n, n, 1, 4}, Storage::F32, build);
  const auto got = from_device(d.table, d.layout.table_floats);
  const size_t Wp = n + 1;
  std::vector<long double> row(Wp, 0.0L);  // S row y of the exact table
  double worst = 0;
  int wx = 0, wy = 0;
  for (int y = 0; y <= n; ++y) {
    if (y > 0) {
      long double t = 0;
      for (int x = 0; x < n; ++x) {
        t += host[size_t(y - 1) * n + x];
        row[x + 1] += t;
      }
    }
    for (int x = 1; x <= n; ++x) {
      const long double v =
          (long double)got[d.layout.at(0, false, x, y)] + (long double)got[d.layout.at(0, true, x, y)];
      if (y == 0) {
        ASSERT_EQ(v, 0.0L);
        continue;
      }
      const double rel = double(fabsl(v - row[x]) / row[x]);
      if (rel > worst) {
        worst = rel;
        wx = x;
        wy = y;
      }
    }
  }
  std::printf("[ SAT 4096x4096 %s ] max |entry error| / S = %.3g (at %d,%d)\n",
              accumulator == SatAccumulator::FloatFloat ? "float-float"
              : schedule == SatSchedule::TwoLaunch      ? "double, two launches"
                                                        : "double",
              worst, wx, wy);
  EXPECT_LT(worst, 1e-12);
}

TEST(SatLarge, EntriesAt4096MatchALongDoubleTable) { expect_large_table_exact(SatAccumulator::Auto); }
TEST(SatLarge, FloatFloatEntriesAt4096MatchALongDoubleTable) { expect_large_table_exact(SatAccumulator::FloatFloat); }
TEST(SatLarge, TwoLaunchEntriesAt4096MatchALongDoubleTable) {
  expect_large_table_exact(SatAccumulator::Auto, SatSchedule::TwoLaunch);
}

// Box lookups (lookup.clh, sf_lookup_box) against the brute-force area-weighted mean at random
// centres and footprints, including boxes past the edges (clamp-to-edge). Values in [0,1) with a
// smooth gradient (a worst case for plain float prefix sums: every prefix grows like x*y).
// Documented bound (docs/lookups.md): |error| <= 2.5e-7 * max|value|. Measured with the double
// corner arithmetic (devices with cl_khr_fp64) 8.4e-8 at 2048 and 6.4e-8 at 4096 (float-float:
// 9.4e-8, 9.5e-8): the table entries (2^-47 relative) leave the float32 rounding of the mean
// (half an ulp, 3e-8 at 0.5) and of the area as the largest terms; plain float32 prefix
// sums miss this bound by four orders of magnitude at 4096 (their entries reach 8e6).
struct BoxCase {
  int size;
  int boxes;
};
class SatBox : public ::testing::TestWithParam<BoxCase> {};

void expect_box_means_within_bound(int n, int boxes, const char* label) {
  std::vector<float> host(size_t(n) * n);
  std::mt19937 rng(n);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) host[size_t(y) * n + x] = 0.5f * dist(rng) + 0.25f * float(x + y) / n;
  const double vmax = 1.0;
  const ImageShape shape{n, n, 1, 4};
  cl::Buffer img = to_device(host);
  const DeviceSat sat = device_sat(img, shape);

  std::vector<float> u(boxes), v(boxes), f(boxes);
  std::uniform_real_distribution<float> coord(-0.02f, 1.02f), logf(0.0f, 7.0f);
  for (int i = 0; i < boxes; ++i) {
    u[i] = coord(rng);
    v[i] = coord(rng);
    f[i] = i % 4 == 0 ? 1.0f : std::exp2(logf(rng));  // 1 .. 128 texels
  }
  LookupBuffers lk;
  lk.kind = Lookup::Sat;
  lk.sat = sat.table;
  lk.footprint = to_device(f);
  cl::Buffer out(runtime().context(), CL_MEM_READ_WRITE, boxes * sizeof(float));
  enqueue_lookup_points(runtime(), Storage::F32, shape, boxes, lk, img, to_device(u), to_device(v), out).wait();
  const auto got = from_device(out, boxes);

  ref::Planes plane(n, n, 1);  // the reference reads the same float values
  for (size_t i = 0; i < host.size(); ++i) plane.data[i] = host[i];
  double worst = 0;
  for (int i = 0; i < boxes; ++i) {
    const double want = ref::box_mean(plane, 0, u[i], v[i], f[i]);
    worst = std::max(worst, std::abs(got[i] - want));
    ASSERT_NEAR(got[i], want, 2.5e-7 * vmax) << "box " << i << " u=" << u[i] << " v=" << v[i] << " f=" << f[i];
  }
  std::printf("[ SAT %dx%d%s ] max |box error| = %.3g x max|value| over %d boxes\n", n, n, label, worst / vmax, boxes);
}

TEST_P(SatBox, BoxMeansMatchBruteForceWithinTheBound) {
  const auto [n, boxes] = GetParam();
  expect_box_means_within_bound(n, boxes, "");
}

INSTANTIATE_TEST_SUITE_P(Large, SatBox, ::testing::Values(BoxCase{2048, 3000}, BoxCase{4096, 3000}));

// A device without cl_khr_fp64 end to end: the table's float-float accumulator and the box
// lookup's float-float corners (Runtime::set_without_fp64), within the same bound.
TEST(SatWithoutFp64, BoxMeansMatchBruteForceWithinTheBound) {
  struct WithoutFp64 {
    WithoutFp64() { runtime().set_without_fp64(true); }
    ~WithoutFp64() { runtime().set_without_fp64(false); }
  } guard;
  ASSERT_FALSE(runtime().info().fp64);
  expect_box_means_within_bound(2048, 3000, ", no fp64");
}

// The table over every basis storage (the table itself is float-float): the stored texels as
// sf_load reads them, summed exactly to float-float accuracy. Sizes cross the 8x8 blocks, the
// bands and their ragged edges.
class SatStorage : public ::testing::TestWithParam<std::tuple<Storage, Size>> {};

TEST_P(SatStorage, TableMatchesTheReference) {
  const auto [storage, s] = GetParam();
  const StoredImage img = random_stored(size_t(s.w) * s.h * s.channels, storage, s.w * 13 + s.h);
  const DeviceSat d = device_sat(stored_buffer(img), {s.w, s.h, s.channels, storage_bytes(storage)}, storage);
  ref::Planes in(s.w, s.h, s.channels);
  for (size_t i = 0; i < img.values.size(); ++i) in.data[i] = img.values[i];
  const auto got = from_device(d.table, d.layout.table_floats);
  const ref::Planes want = ref::sat_table(in);
  expect_table(got, d.layout, want, storage_name(storage));
}

INSTANTIATE_TEST_SUITE_P(
    Storages, SatStorage,
    ::testing::Combine(::testing::Values(Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8),
                       ::testing::Values(Size{1, 1, 1}, Size{7, 9, 2}, Size{37, 100, 1}, Size{300, 257, 3})));

// Box lookups over an f16 / unorm8 basis: the table of the stored values (lookup.clh reads the
// table, not the basis), within the same bound as f32.
TEST(SatStorage, BoxMeansOfStoredBasesMatchBruteForce) {
  const int n = 301;
  for (Storage storage : {Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
    const StoredImage img = random_stored(size_t(n) * n, storage, 7);
    const ImageShape shape{n, n, 1, storage_bytes(storage)};
    cl::Buffer level0 = stored_buffer(img);
    const DeviceSat sat = device_sat(level0, shape, storage);
    const int boxes = 500;
    std::vector<float> u(boxes), v(boxes), f(boxes);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> coord(-0.02f, 1.02f), logf(0.0f, 7.0f);
    for (int i = 0; i < boxes; ++i) {
      u[i] = coord(rng);
      v[i] = coord(rng);
      f[i] = std::exp2(logf(rng));
    }
    LookupBuffers lk;
    lk.kind = Lookup::Sat;
    lk.sat = sat.table;
    lk.footprint = to_device(f);
    cl::Buffer out(runtime().context(), CL_MEM_READ_WRITE, boxes * sizeof(float));
    enqueue_lookup_points(runtime(), storage, shape, boxes, lk, level0, to_device(u), to_device(v), out).wait();
    const auto got = from_device(out, boxes);
    ref::Planes plane(n, n, 1);
    for (size_t i = 0; i < img.values.size(); ++i) plane.data[i] = img.values[i];
    for (int i = 0; i < boxes; ++i)
      ASSERT_NEAR(got[i], ref::box_mean(plane, 0, u[i], v[i], f[i]), 2.5e-7)
          << storage_name(storage) << " box " << i << " f=" << f[i];
  }
}

}  // namespace
}  // namespace sf::test

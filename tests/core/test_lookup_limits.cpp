// Lookup limits (docs/numerics.md, "Lookup limits"): a summed-area table of an exponential basis
// (esm, evsm) is refused where the map's depth range passes what its entries hold
// (MethodDesc::sat_limit), by sf::filter and by the Pipeline, before anything runs; at the limit
// the result meets the documented bound. Also the depth-range reduction the pipeline uses
// without a stated range.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// Depths over [lo, hi]: the top-left quadrant at hi (the largest entries every bottom-right box
// subtracts), the rest 8x8 blocks, flat at lo or at hi, or lo with noise of 1% of the span.
HostImage limit_map(int size, float lo, float hi) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(0.0f, 0.01f);
  HostImage m(size, size, 1);
  std::vector<int> block(size_t(size / 8 + 1) * (size / 8 + 1));
  for (auto& b : block) b = int(rng() % 4);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int b = block[size_t(y / 8) * (size / 8 + 1) + x / 8];
      const bool bright = (x < size / 2 && y < size / 2) || b == 0;
      m.at(x, y) = bright ? hi : b == 1 ? lo : lo + (hi - lo) * noise(rng);
    }
  return m;
}

// Receivers in the bottom-right quadrant, footprints 1 .. 8, on their texel's depth or just
// behind it (down to the offsets where a Chebyshev bound turns).
Receivers limit_receivers(const HostImage& m, int n) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> pos(0.5f, 1.0f);
  const float fs[] = {1.0f, 2.0f, 3.5f, 8.0f};
  const float offsets[] = {0.0f, 2e-5f, 5e-5f, 2e-4f, 1e-3f, 5e-3f};
  Receivers rx;
  rx.width = n;
  rx.height = 1;
  rx.has_footprint = true;
  for (int i = 0; i < n; ++i) {
    const float u = pos(rng), v = pos(rng);
    rx.u.push_back(u);
    rx.v.push_back(v);
    rx.f.push_back(fs[rng() % 4]);
    const int x = std::min(int(u * m.width), m.width - 1), y = std::min(int(v * m.height), m.height - 1);
    rx.d.push_back(std::min(m.at(x, y) + offsets[rng() % 6], 1.0f));
  }
  return rx;
}

// The widest depth range [hi - span, hi] the sat limit accepts for `o` on a size^2 map (bisection).
float widest_span(const FilterOptions& o, int size, float hi) {
  float ok = 0.0f, bad = hi;
  for (int i = 0; i < 40; ++i) {
    const float mid = 0.5f * (ok + bad);
    (sat_refusal(o, SatMap{{hi - mid, hi}, size, size, runtime().info().fp64}).empty() ? ok : bad) = mid;
  }
  return ok;
}

std::string refusal_of(const FilterOptions& o, const HostImage& m, const Receivers& rx) {
  try {
    filter(runtime_ptr(), o, m, rx);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

TEST(LookupLimits, SatRefusalNamesTheLimitAndTheWayOut) {
  FilterOptions o;
  o.esm.c = 80.0f;
  o.lookup.kind = Lookup::Sat;
  const HostImage m = limit_map(64, 0.2f, 0.7f);
  const Receivers rx = limit_receivers(m, 10);
  std::string why = refusal_of(o, m, rx);
  for (const char* part : {"FilterOptions::lookup.kind sat", "esm", "64x64", "exp(40)",
                           "FilterOptions::lookup.kind mips", "FilterOptions::esm.c <= "})
    EXPECT_NE(why.find(part), std::string::npos) << part << " missing from: " << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  // Past the float32 range of the entries: c = 174 with depths up to 1 sums past FLT_MAX.
  o.esm.c = 174.0f;
  why = refusal_of(o, limit_map(64, 0.9f, 1.0f), rx);
  EXPECT_NE(why.find("overflow"), std::string::npos) << why;
  // evsm: the second moment's span, and the negative side's exponent where it is the one past.
  for (const char* method : {"evsm2", "evsm4"}) {
    FilterOptions e;
    e.method = method;
    e.evsm.pos = 40.0f;
    e.lookup.kind = Lookup::Sat;
    why = refusal_of(e, m, rx);
    EXPECT_NE(why.find(std::string(method) + " with FilterOptions::evsm.pos 40"), std::string::npos) << why;
  }
  FilterOptions e;
  e.method = "evsm4";
  e.lookup.kind = Lookup::Sat;
  e.evsm.pos = 1.0f;
  e.evsm.neg = 42.0f;
  why = refusal_of(e, m, rx);
  EXPECT_NE(why.find("FilterOptions::evsm.neg"), std::string::npos) << why;
  // The other lookups and the bounded bases have no such limit.
  o.esm.c = 80.0f;
  o.lookup.kind = Lookup::Mips;
  EXPECT_EQ(refusal_of(o, m, rx), "");
  for (const char* method : {"vsm", "msm", "csm", "pcf"}) {
    FilterOptions b;
    b.method = method;
    b.lookup.kind = Lookup::Sat;
    EXPECT_EQ(refusal_of(b, m, rx), "") << method;
  }
}

// The Pipeline refuses too: at construction where FilterOptions::depth_range states the range,
// else in prefilter() from the device's own reduction of the map, before it enqueues anything.
TEST(LookupLimits, PipelineRefusesFromAStatedOrMeasuredRange) {
  FilterOptions o;
  o.lookup.kind = Lookup::Sat;
  const HostImage m = limit_map(64, 0.0f, 1.0f);
  FilterOptions stated = o;
  stated.depth_range = depth_range(m);
  EXPECT_THROW(Pipeline(runtime_ptr(), stated, 64, 64), InputError);
  EXPECT_THROW(Pipeline::plan(runtime(), stated, 64, 64), InputError);
  Pipeline pipe(runtime_ptr(), o, 64, 64);  // no range yet: nothing to refuse
  cl::Buffer depth = to_device(m.data);
  EXPECT_THROW(pipe.prefilter(depth), InputError);
  // A map within the limit runs.
  const HostImage flat = limit_map(64, 0.5f, 0.55f);
  cl::Buffer ok = to_device(flat.data);
  EXPECT_NO_THROW(pipe.prefilter(ok).wait());
}

// The device reduction equals the host scan, skips NaN and infinities, covers a partial last run
// of a work-item and says "no finite depth" as min > max.
TEST(LookupLimits, DeviceDepthRangeMatchesTheHost) {
  for (int size : {1, 7, 300}) {
    HostImage m = random_depth(size, size + 3, unsigned(size), 0.25f, 0.75f);
    m.data[0] = NAN;
    m.data.back() = INFINITY;
    m.data[m.data.size() / 2] = -INFINITY;
    const MapRange host = depth_range(m);
    const MapRange device = depth_range(runtime(), to_device(m.data), m.data.size());
    EXPECT_EQ(device.min, host.min) << size;
    EXPECT_EQ(device.max, host.max) << size;
    EXPECT_GE(host.min, 0.25f);
    EXPECT_LE(host.max, 0.75f);
  }
  const std::vector<float> none(5000, NAN);
  const MapRange r = depth_range(runtime(), to_device(none), none.size());
  EXPECT_GT(r.min, r.max);
  EXPECT_EQ(r.span(), 0.0f);
}

// Allowed at the limit: the widest range the limit accepts, on the adversarial map, against the
// double twin on the same stored basis and weights. esm: its float bound 2e-5 + 1e-7 c plus the
// table's share 1e-3; both accumulators. evsm2: the table may add no more than float32 lookups
// carry, so evsm's own bound, 2^-23 / (v_min c)^2 (docs/numerics.md).
TEST(LookupLimits, SatAtTheLimitMeetsItsBound) {
  for (bool fp64 : {true, false}) {
    runtime().set_without_fp64(!fp64);
    for (const char* method : {"esm", "evsm2"}) {
      FilterOptions o;
      o.method = method;
      o.lookup.kind = Lookup::Sat;
      o.esm.c = 80.0f;
      o.evsm.pos = 40.0f;
      o.vsm.min_variance = 1e-4f;               // evsm's relative floor of the bound below
      o.esm_classify.mode = EsmClassify::None;  // the double twin has no classification stage
      const bool esm = o.method == "esm";
      const float span = widest_span(o, 128, 0.8f);
      ASSERT_GT(span, 0.0f) << method;
      const HostImage m = limit_map(128, 0.8f - span, 0.8f);
      const Receivers rx = limit_receivers(m, 2000);
      const std::vector<float> got = filter(runtime_ptr(), o, m, rx).visibility.data;
      const std::vector<double> want = ref::filter(o, m, rx);
      const double floor = 1e-4 * o.evsm.pos;
      const double bound = esm ? 2e-5 + 1e-7 * o.esm.c + 1e-3 : std::ldexp(1.0, -23) / (floor * floor);
      double worst = 0;
      for (size_t i = 0; i < got.size(); ++i) worst = std::max(worst, std::fabs(got[i] - want[i]));
      EXPECT_LE(worst, bound) << method << (fp64 ? " double" : " float-float") << " span " << span;
      // One step past the limit is refused.
      EXPECT_NE(refusal_of(o, limit_map(128, 0.8f - 1.01f * span, 0.8f), rx), "") << method;
    }
  }
  runtime().set_without_fp64(false);
}

}  // namespace
}  // namespace sf::test

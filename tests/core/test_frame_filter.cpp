// FrameFilter: a sequence of frames on one warm pipeline gives what filter() gives for each frame
// alone, bit for bit, whether the device reads the host's vectors in place or copies of them;
// its buffers are reallocated exactly when the map's size or the receivers' count changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"

namespace sf::test {
namespace {

// Receivers on a w x h grid over the map, depth d, with footprints and ndl (some facing away).
Receivers points(int w, int h, float d, unsigned seed) {
  Receivers rx;
  rx.width = w;
  rx.height = h;
  rx.has_footprint = rx.has_ndl = true;
  const HostImage jitter = random_depth(w, h, seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float j = jitter.at(x, y);
      rx.u.push_back((x + j) / w);
      rx.v.push_back((y + 1.0f - j) / h);
      rx.d.push_back(x == 0 && y == 0 ? std::numeric_limits<float>::quiet_NaN() : d + 0.1f * j);
      rx.f.push_back(1.0f + 4.0f * j);
      rx.ndl.push_back(j < 0.1f ? -0.5f : 0.8f);
    }
  return rx;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  // memcmp takes no null pointer, which an empty vector may give.
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

struct Frame {
  HostImage depth;
  Receivers rx;
};

void expect_frames_match_filter(FrameFilter::HostMemory memory, const FilterOptions& o) {
  // Three sizes, with repeats: 48x40 twice, 64x32, 48x40 again, then a grid frame.
  std::vector<Frame> frames;
  frames.push_back({random_depth(48, 40, 1, 0.2f, 0.9f), points(17, 13, 0.6f, 2)});
  frames.push_back({random_depth(48, 40, 3, 0.2f, 0.9f), points(17, 13, 0.5f, 4)});
  frames.push_back({random_depth(64, 32, 5, 0.2f, 0.9f), points(9, 7, 0.55f, 6)});
  frames.push_back({random_depth(48, 40, 7, 0.2f, 0.9f), points(17, 13, 0.6f, 8)});
  Receivers grid;
  grid.width = 48;
  grid.height = 40;
  grid.grid = true;
  grid.d = random_depth(48, 40, 9, 0.3f, 0.8f).data;
  frames.push_back({random_depth(48, 40, 10, 0.2f, 0.9f), grid});
  const int expected_allocations[] = {1, 1, 2, 3, 4};  // the grid frame: new receiver buffers

  FrameFilter batch(runtime_ptr(), o, memory);
  EXPECT_EQ(batch.zero_copy(), memory == FrameFilter::HostMemory::ZeroCopy);
  for (size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const FilterResult got = batch.run(frames[i].depth, frames[i].rx);
    const FilterResult want = filter(runtime_ptr(), o, frames[i].depth, frames[i].rx);
    EXPECT_EQ(batch.allocations(), expected_allocations[i]);
    ASSERT_EQ(got.visibility.width, frames[i].rx.width);
    EXPECT_TRUE(same_bits(got.visibility.data, want.visibility.data));
    EXPECT_TRUE(same_bits(got.flags.data, want.flags.data));
    EXPECT_EQ(got.flagged, want.flagged);
    EXPECT_EQ(got.background, want.background);
    EXPECT_EQ(got.facing_away, want.facing_away);
    EXPECT_EQ(got.outside, want.outside);
    // Not a constant image: the frames have shadowed and lit receivers.
    float lo = 1, hi = 0;
    for (float v : got.visibility.data) lo = std::min(lo, v), hi = std::max(hi, v);
    EXPECT_LT(lo, 0.1f);
    EXPECT_GT(hi, 0.9f);
  }
}

FilterOptions esm_mips() {
  FilterOptions o;
  o.method = "esm";
  o.blur.radius = 2;
  o.lookup.kind = Lookup::Mips;
  return o;
}

TEST(FrameFilter, CopiedFramesEqualFilterBitForBit) {
  expect_frames_match_filter(FrameFilter::HostMemory::Copy, esm_mips());
}

TEST(FrameFilter, ZeroCopyFramesEqualFilterBitForBit) {
  expect_frames_match_filter(FrameFilter::HostMemory::ZeroCopy, esm_mips());
  FilterOptions o;
  o.method = "pcf";
  expect_frames_match_filter(FrameFilter::HostMemory::ZeroCopy, o);
  o.method = "evsm4";
  o.lookup.kind = Lookup::Sat;
  o.evsm.pos = 2.0f;
  o.evsm.neg = 2.0f;
  expect_frames_match_filter(FrameFilter::HostMemory::Copy, o);
}

// On a CPU device a new pipeline's buffers are faulted in before its first frame (resident.hpp):
// the fills are reported as that frame's `resident`, not in any stage, and a frame on the same
// buffers reports none. The ESM flags, allocated by the first frame of a receiver count larger
// than any before, are faulted in by that frame.
TEST(FrameFilter, NewBuffersAreFaultedInBeforeTheirFirstFrame) {
  if (runtime_ptr()->info().type != "CPU") GTEST_SKIP() << "buffers are host pages on CPU devices only";
  FrameFilter batch(runtime_ptr(), esm_mips());
  const HostImage depth = random_depth(48, 40, 1, 0.2f, 0.9f);
  const FilterResult first = batch.run(depth, points(17, 13, 0.6f, 2));
  EXPECT_GT(first.times.resident, 0.0);
  EXPECT_GT(first.times.transform, 0.0);
  const FilterResult second = batch.run(depth, points(17, 13, 0.5f, 4));
  EXPECT_EQ(second.times.resident, 0.0);
  const FilterResult more = batch.run(depth, points(30, 20, 0.5f, 6));  // new flags only
  EXPECT_GT(more.times.resident, 0.0);
  EXPECT_EQ(batch.allocations(), 2);
  // Not counted as a stage.
  StageTimes t = more.times;
  t.resident = 0;
  EXPECT_EQ(t.total(), more.times.total());
}

// A frame whose depth range the lookup cannot hold is refused alone: the frames around it run.
TEST(FrameFilter, RefusedFrameLeavesTheNextOneRunning) {
  FilterOptions o;
  o.method = "esm";
  o.esm.c = 80.0f;
  o.lookup.kind = Lookup::Sat;
  o.esm_classify.mode = EsmClassify::None;
  FrameFilter batch(runtime_ptr(), o);
  const Receivers rx = points(11, 9, 0.6f, 3);
  const HostImage narrow = random_depth(32, 32, 1, 0.50f, 0.55f);  // c span 4: held
  const HostImage wide = random_depth(32, 32, 2, 0.0f, 1.0f);      // c span 80: refused
  const FilterResult first = batch.run(narrow, rx);
  EXPECT_THROW(batch.run(wide, rx), InputError);
  const FilterResult again = batch.run(narrow, rx);
  EXPECT_TRUE(same_bits(first.visibility.data, again.visibility.data));
  EXPECT_EQ(batch.allocations(), 1);
}

}  // namespace
}  // namespace sf::test

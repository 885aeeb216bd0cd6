// Mip, z-max and z-min pyramids (kernels/pyramid.cl) against the scalar reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lookups.hpp"
#include "sf_test_env.hpp"
#include "test_methods_common.hpp"
#include "shadowfilter/mips.hpp"

namespace sf::test {
namespace {

struct Size {
  int w, h, channels;
};

ref::Planes random_planes(const Size& s, unsigned seed) {
  ref::Planes p(s.w, s.h, s.channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (auto& v : p.data) v = dist(rng);
  return p;
}

std::vector<float> to_float(const ref::Planes& p) { return std::vector<float>(p.data.begin(), p.data.end()); }

// Builds the chain on the device; returns every level (0 = input) as planes.
std::vector<ref::Planes> device_chain(const ref::Planes& in, Reduce op) {
  const MipLayout L = mip_layout(in.width, in.height, in.channels);
  cl::Buffer level0 = to_device(to_float(in));
  cl::Buffer chain(runtime().context(), CL_MEM_READ_WRITE, std::max<size_t>(L.chain_values, 1) * sizeof(float));
  enqueue_pyramid(runtime(), op, Storage::F32, {}, {in.width, in.height, in.channels, 4}, level0, chain).wait();
  const auto host = from_device(chain, std::max<size_t>(L.chain_values, 1));
  std::vector<ref::Planes> out{in};
  for (int k = 1; k <= L.top(); ++k) {
    ref::Planes p(L.levels[k].width, L.levels[k].height, in.channels);
    for (size_t i = 0; i < p.data.size(); ++i) p.data[i] = host[L.levels[k].offset + i];
    out.push_back(p);
  }
  return out;
}

class Pyramid : public ::testing::TestWithParam<Size> {};

// Mean: each level is 0.25 ((a + b) + (c + d)) of float values; level k carries k roundings of
// half an ulp each (relative 6e-8): relative tolerance 1e-6 over <= 13 levels. Max / min are exact.
TEST_P(Pyramid, EveryLevelMatchesTheReference) {
  const Size s = GetParam();
  const ref::Planes in = random_planes(s, s.w * 7 + s.h);
  for (int op : {0, 1, 2}) {
    const auto got = device_chain(in, static_cast<Reduce>(op));
    const auto want = ref::mip_chain(in, op);
    ASSERT_EQ(got.size(), want.size());
    for (size_t k = 1; k < want.size(); ++k) {
      ASSERT_EQ(got[k].width, want[k].width);
      ASSERT_EQ(got[k].height, want[k].height);
      for (size_t i = 0; i < want[k].data.size(); ++i) {
        if (op == 0)
          ASSERT_NEAR(got[k].data[i], want[k].data[i], 1e-6 * std::abs(want[k].data[i]) + 1e-7)
              << "level " << k << " index " << i << " size " << s.w << "x" << s.h;
        else
          ASSERT_EQ(got[k].data[i], float(want[k].data[i])) << "op " << op << " level " << k << " index " << i;
      }
    }
  }
}

// Sizes: 1x1 (no level), thin and odd ones, non-powers of two, and maps above 128 texels a side
// (the 32x32 tile kernel, interior and edge tiles, before the tail kernel), several channels.
INSTANTIATE_TEST_SUITE_P(Sizes, Pyramid,
                         ::testing::Values(Size{1, 1, 1}, Size{1, 9, 1}, Size{13, 1, 2}, Size{2, 2, 1}, Size{3, 5, 1},
                                           Size{33, 17, 3}, Size{128, 128, 1}, Size{129, 3, 1}, Size{300, 129, 2},
                                           Size{257, 511, 1}, Size{1000, 37, 1}, Size{517, 300, 4}, Size{256, 96, 2}));

// Conservative: every z-max texel >= every level-0 texel it covers (level-k texel (i, j) covers
// [i 2^k, (i+1) 2^k) x [j 2^k, (j+1) 2^k) clipped to the map), z-min likewise <=.
TEST(Pyramid, ZMaxAndZMinBoundTheTexelsTheyCover) {
  const HostImage depth = random_depth(301, 173, 5);
  ref::Planes in(depth.width, depth.height, 1);
  for (size_t i = 0; i < depth.data.size(); ++i) in.data[i] = depth.data[i];
  const auto zmax = device_chain(in, Reduce::Max), zmin = device_chain(in, Reduce::Min);
  for (size_t k = 1; k < zmax.size(); ++k)
    for (int y = 0; y < depth.height; ++y)
      for (int x = 0; x < depth.width; ++x) {
        const float z = depth.at(x, y);
        ASSERT_GE(zmax[k].at(0, x >> k, y >> k), z) << "level " << k << " texel " << x << "," << y;
        ASSERT_LE(zmin[k].at(0, x >> k, y >> k), z) << "level " << k << " texel " << x << "," << y;
      }
  // And tight: the top texel is the global max / min.
  EXPECT_EQ(zmax.back().data[0], *std::max_element(depth.data.begin(), depth.data.end()));
  EXPECT_EQ(zmin.back().data[0], *std::min_element(depth.data.begin(), depth.data.end()));
}

TEST(Pyramid, LayoutHalvesRoundingUpDownToOneTexel) {
  const MipLayout L = mip_layout(5, 3, 2);
  ASSERT_EQ(L.top(), 3);
  EXPECT_EQ(L.levels[1].width, 3);
  EXPECT_EQ(L.levels[1].height, 2);
  EXPECT_EQ(L.levels[2].width, 2);
  EXPECT_EQ(L.levels[2].height, 1);
  EXPECT_EQ(L.levels[3].width, 1);
  EXPECT_EQ(L.levels[2].offset, 2u * 3 * 2);
  EXPECT_EQ(L.chain_values, 2u * (6 + 2 + 1));
  EXPECT_EQ(mip_layout(1, 1, 1).chain_values, 0u);
}

// The mip chain in every storage: levels are computed in float from the (decoded) level 0 and
// rounded once when stored, as the reference quantises its double levels: at most one storage
// step apart (two correct roundings of values within float error of each other), exact max/min.
class PyramidStorage : public ::testing::TestWithParam<std::tuple<Storage, Size>> {};

TEST_P(PyramidStorage, EveryLevelMatchesTheReference) {
  const auto [storage, s] = GetParam();
  const StoredImage img = random_stored(size_t(s.w) * s.h * s.channels, storage, s.w * 5 + s.h);
  ref::Planes in(s.w, s.h, s.channels);
  for (size_t i = 0; i < img.values.size(); ++i) in.data[i] = img.values[i];
  const MipLayout L = mip_layout(s.w, s.h, s.channels);
  for (int op : {0, 1, 2}) {
    cl::Buffer chain(runtime().context(), CL_MEM_READ_WRITE,
                     std::max<size_t>(L.chain_values, 1) * storage_bytes(storage));
    enqueue_pyramid(runtime(), static_cast<Reduce>(op), storage, {}, {s.w, s.h, s.channels, storage_bytes(storage)},
                    stored_buffer(img), chain)
        .wait();
    const auto got = read_stored(chain, std::max<size_t>(L.chain_values, 1), storage);
    const auto want = ref::mip_chain(in, op);
    ASSERT_EQ(int(want.size()) - 1, L.top());
    for (int k = 1; k <= L.top(); ++k)
      for (size_t i = 0; i < want[k].data.size(); ++i) {
        const double w = want[k].data[i], q = ref::quantise(w, storage);
        const double tol = op == 0 ? storage_step(w, storage) + 1e-6 * std::abs(w) : 0.0;
        ASSERT_NEAR(got[L.levels[k].offset + i], q, tol)
            << storage_name(storage) << " op " << op << " level " << k << " index " << i;
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Storages, PyramidStorage,
                         ::testing::Combine(::testing::Values(Storage::F16, Storage::Unorm16, Storage::Unorm8),
                                            ::testing::Values(Size{1, 1, 1}, Size{3, 5, 2}, Size{33, 17, 1},
                                                              Size{300, 129, 2}, Size{517, 300, 1})));

}  // namespace
}  // namespace sf::test

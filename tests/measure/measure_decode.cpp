// What decoding one frame's files costs alone, on one thread of the batch's kind (docs/batch.md:
// a batch's wall time per frame against the larger of its device time and this; sf_measure,
// run by scripts/batch_bench.sh; not part of the test suite).
//   SF_DECODE_MAP=map.exr [SF_DECODE_RUNS=5] sf_measure --gtest_filter='Decode.*'
// Prints the median milliseconds of io::load_depth_map over the runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "image_io.hpp"

namespace sf::test {
namespace {

TEST(Decode, ShadowMapMedianMs) {
  const char* map = std::getenv("SF_DECODE_MAP");
  if (!map) GTEST_SKIP() << "SF_DECODE_MAP names no map";
  const int runs = std::getenv("SF_DECODE_RUNS") ? std::atoi(std::getenv("SF_DECODE_RUNS")) : 5;
  std::vector<double> ms;
  for (int i = 0; i < std::max(runs, 1); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const HostImage depth = io::load_depth_map(map, {});
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ASSERT_GT(depth.texels(), 0u);
  }
  std::sort(ms.begin(), ms.end());
  std::printf("decode_ms %.1f\n", ms[ms.size() / 2]);
}

}  // namespace
}  // namespace sf::test

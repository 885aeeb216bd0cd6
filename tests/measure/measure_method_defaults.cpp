// Measurements behind the methods' measured defaults (docs/methods.md): csm's offset and scale per
// order, msm's unorm16 depth bias. Run: build/tests/sf_measure --gtest_filter='MethodDefaults*'
#include "csm_scenes.hpp"
#include "shadowfilter/frame_filter.hpp"

namespace sf::test {
using namespace csm_scenes;
namespace {

// The measurement behind the defaults in host/src/methods/ (docs/methods.md). Per order and
// scale, the least offset (on a grid) that keeps every lit receiver of both scenes
// >= 1 - 1/255 (more offset only lights more of the shadow), with its RMSE / p99 / mean error per
// scene. The defaults are one of these pairs per order, chosen jointly (docs/methods.md): the
// sequence over M = 1, 2, 4, 8, 16, 32 whose four errors (RMSE and p99 on both scenes) fall by >= 2%
// from each order to the next, with the least sum of their logarithms.
TEST(MethodDefaults, CsmOffsetAndScale) {
  for (int k = 0; k < 2; ++k)
    std::printf("%s: planar receivers %zu lit, %zu scored, %zu next to empty map\n", kScenes[k], csm_scene(k).n_lit,
                csm_scene(k).n_scored, csm_scene(k).n_edge);
  std::vector<float> offsets;
  for (int i = 0; i <= 40; ++i) offsets.push_back(0.0025f * i);       // 0 .. 0.1
  for (int i = 1; i <= 20; ++i) offsets.push_back(0.1f + 0.01f * i);  // .. 0.3
  for (int i = 1; i <= 8; ++i) offsets.push_back(0.3f + 0.025f * i);  // .. 0.5
  const float scales[] = {1.0f, 1.025f, 1.05f, 1.075f, 1.1f, 1.125f, 1.15f, 1.2f, 1.25f, 1.3f, 1.4f, 1.5f, 1.75f, 2.0f};
  for (int M : kOrders) {
    CsmRun runs[] = {CsmRun(csm_scene(0), M), CsmRun(csm_scene(1), M)};
    // f per offset and scene at scale 1; scales are applied here.
    std::vector<std::vector<float>> f[2];
    for (int k = 0; k < 2; ++k)
      for (float o : offsets) f[k].push_back(runs[k].visibility(o, 1.0f));
    for (float sc : scales) {
      for (size_t j = 0; j < offsets.size(); ++j) {
        const CsmScore a = score(csm_scene(0), f[0][j], sc), b = score(csm_scene(1), f[1][j], sc);
        if (!a.lit_ok() || !b.lit_ok()) continue;
        std::printf(
            "M=%2d scale %.2f offset %.4f | %s rmse %.4f p99 %.4f mean %.4f lit %.4f | "
            "%s rmse %.4f p99 %.4f mean %.4f lit %.4f\n",
            M, sc, offsets[j], kScenes[0], a.rmse, a.p99, a.mean, a.min_lit, kScenes[1], b.rmse, b.p99, b.mean,
            b.min_lit);
        break;  // the least offset that keeps both scenes lit
      }
    }
    std::fflush(stdout);
  }
}

// msm in unorm16: quantising the optimised moments (steps of 1.5e-5) moves the power moments by
// ~1e-5, against a moment bias of 6e-5; a flat receiver near depth 0 then falls in its own shadow.
// The smallest depth bias that keeps d = z lit for z = k/256 is the unorm16 default.
TEST(MethodDefaults, MsmUnorm16DepthBias) {
  HostImage depth(257, 1, 1);
  for (int k = 0; k <= 256; ++k) depth.at(k, 0) = k / 256.0f;
  Receivers rx;
  rx.grid = true;
  rx.width = 257;
  rx.height = 1;
  rx.d = depth.data;
  for (const char* name : {"msm", "msm-hausdorff"}) {
    for (float bias : {0.0f, 1e-5f, 2e-5f, 5e-5f, 1e-4f, 2e-4f, 5e-4f, 1e-3f, 2e-3f, 5e-3f}) {
      FilterOptions opt;
      opt.method = name;
      opt.storage = Storage::Unorm16;
      opt.depth_test.bias = bias;
      const auto v = filter(runtime_ptr(), opt, depth, rx).visibility.data;
      const float lowest = *std::min_element(v.begin(), v.end());
      std::printf("%s unorm16 bias %g: lowest %.6f at z = %g\n", name, bias, lowest,
                  (std::min_element(v.begin(), v.end()) - v.begin()) / 256.0);
    }
  }
}

}  // namespace
}  // namespace sf::test

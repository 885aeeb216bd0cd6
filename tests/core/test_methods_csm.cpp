// CSM on the bundled scenes: the chosen defaults keep lit receivers lit, and the error falls with
// the order (the measurement that chose them: tests/measure/measure_method_defaults.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "image_io.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/pipeline.hpp"
#include "csm_scenes.hpp"
#include "test_methods_common.hpp"

namespace sf::test {

using namespace csm_scenes;

namespace {

// The defaults keep lit receivers lit on both scenes, and the error against s_ref (RMSE and p99)
// falls strictly with the order M = 1, 2, 4, 8, 16, 32 (values in docs/methods.md).
TEST(CsmDefaults, LitReceiversLitAndErrorFallsWithOrder) {
  for (int k = 0; k < 2; ++k) {
    double last_rmse = 1e9, last_p99 = 1e9;
    for (int M : kOrders) {
      CsmRun r(csm_scene(k), M);
      const CsmParameters p = csm_parameters(r.opt);
      const CsmScore c = score(csm_scene(k), r.visibility(p.offset, p.scale), 1.0f);
      std::printf("%s M=%2d offset %.4f scale %.2f: rmse %.4f p99 %.4f mean %.4f lit %.5f\n", kScenes[k], M, p.offset,
                  p.scale, c.rmse, c.p99, c.mean, c.min_lit);
      EXPECT_GE(c.min_lit, 1.0f - 1.0f / 255.0f) << kScenes[k] << " M=" << M;
      EXPECT_LT(c.rmse, last_rmse) << kScenes[k] << " M=" << M;
      EXPECT_LT(c.p99, last_p99) << kScenes[k] << " M=" << M;
      last_rmse = c.rmse;
      last_p99 = c.p99;
    }
  }
}

// The unorm transform gives codes straight from the scaled recurrence (csm.clh: unorm8 unclamped,
// its range argued from the error bound). Dense depths over [0, 1] at the highest order (the most
// recurrence drift), 4133 texels so that the last work-item's scalar tail is checked too: every
// code within one of the reference's rounding (float error plus one step, as in test_methods.cpp;
// a code that wrapped past 255 or below 0 would be off by the whole range).
TEST(CsmUnormCodes, DenseDepthsWithinOneCode) {
  HostImage depth(4133, 1, 1);
  for (int i = 0; i < depth.width; ++i) depth.at(i, 0) = float(i) / float(depth.width - 1);
  cl::Buffer z = to_device(depth.data);
  for (Storage st : {Storage::Unorm8, Storage::Unorm16})
    for (int M : {1, 7, 32}) {
      const MethodCase mc{"csm", st, M};
      const FilterOptions opt = mc.options();
      const MethodDesc& m = *sf::method("csm");
      const size_t n = depth.texels() * m.channels(opt);
      cl::Buffer basis(runtime().context(), CL_MEM_READ_WRITE, n * storage_bytes(st));
      enqueue_transform(runtime(), m, opt, depth.width, depth.height, z, basis).wait();
      const auto got = read_stored(basis, n, st);
      const auto want = ref::transform(opt, depth);
      const double step = storage_step(0.5, st), tol = 2e-6 + 6e-7 * M + step;
      double worst = 0;
      for (size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(got[i] - ref::quantise(want.data[i], st)));
      EXPECT_LE(worst, tol) << storage_name(st) << " M=" << M;
    }
}

}  // namespace
}  // namespace sf::test

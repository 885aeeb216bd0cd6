// The measurement behind the --esm-zmax-offset default (docs/lookups.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "image_io.hpp"
#include "lookups.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

FilterOptions classify_options(Lookup kind, int radius, EsmClassify mode) {
  FilterOptions o;  // esm c = 80, the classification's measured case
  o.esm.c = 80.0f;
  o.blur.radius = radius, o.lookup.kind = kind, o.esm_classify.mode = mode;
  return o;
}

// Figure run for the --esm-zmax-offset default (docs/lookups.md): on the bundled scenes' camera
// receivers (c = 80, mips, R = 0..3) the flagged fraction of the in-map receivers at several
// offsets against where ESM actually fails (|v_esm - s_ref| > 0.1, s_ref = pcf with the same
// footprints and evaluate's depth bias 0.01), and the mean |v - s_ref| with and without the fall-back.
// Run: build/tests/sf_measure --gtest_filter='*ZMaxOffsetOnBundledScenes*'
TEST(Classify, ZMaxOffsetOnBundledScenes) {
  const char* env = std::getenv("SF_SCENES");
  std::vector<std::string> scenes;
  std::istringstream names(env ? env : "spheres backyard fence thin");
  for (std::string sname; names >> sname;) scenes.push_back(sname);
  for (const std::string& scene : scenes) {
    const HostImage depth = io::load_depth_map(data_path(scene + "/shadowmap.exr"), {});
    const Receivers rx = io::load_receiver_image(data_path(scene + "/receivers.exr"));
    for (int radius = 0; radius <= 3; ++radius) {
      FilterOptions opt = classify_options(Lookup::Mips, radius, EsmClassify::None);
      const auto esm = filter(runtime_ptr(), opt, depth, rx).visibility.data;
      FilterOptions popt = opt;
      popt.method = "pcf";
      popt.depth_test.bias = 0.01f;  // evaluate's s_ref bias (kDefaultSrefBias): no acne on lit floors
      const auto sref = filter(runtime_ptr(), popt, depth, rx).visibility.data;
      std::vector<char> inside(rx.count()), fails(rx.count());
      size_t n_in = 0, n_fail = 0;
      double err_plain = 0;
      for (size_t i = 0; i < rx.count(); ++i) {
        inside[i] = std::isfinite(rx.d[i]) && rx.u[i] >= 0 && rx.u[i] <= 1 && rx.v[i] >= 0 && rx.v[i] <= 1;
        if (!inside[i]) continue;
        ++n_in;
        const double e = std::abs(esm[i] - sref[i]);
        fails[i] = e > 0.1;
        n_fail += fails[i];
        err_plain += e;
      }
      std::printf("%s R=%d: %zu in-map receivers, ESM fails (|err| > 0.1) on %.2f%%, mean |err| %.4f\n", scene.c_str(),
                  radius, n_in, 100.0 * n_fail / n_in, err_plain / n_in);
      for (EsmClassify mode : {EsmClassify::ZMax, EsmClassify::Threshold})
        for (float offset : {0.002f, 0.005f, 0.01f, 0.02f, 0.03f, 0.05f}) {
          FilterOptions copt = opt;
          copt.esm_classify.mode = mode;
          copt.esm_classify.zmax_offset = offset;
          const auto r = filter(runtime_ptr(), copt, depth, rx);
          size_t flagged = 0, hit = 0;
          double err = 0;
          for (size_t i = 0; i < rx.count(); ++i) {
            if (!inside[i]) continue;
            const bool f = r.flags.data[i] > 0;
            flagged += f;
            hit += f && fails[i];
            err += std::abs(r.visibility.data[i] - sref[i]);
          }
          std::printf("  %-9s offset %.3f: flagged %6.2f%%  recall %5.1f%%  precision %5.1f%%  mean |err| %.4f\n",
                      mode == EsmClassify::ZMax ? "zmax" : "threshold", offset, 100.0 * flagged / n_in,
                      n_fail ? 100.0 * hit / n_fail : 100.0, flagged ? 100.0 * hit / flagged : 0.0, err / n_in);
        }
    }
  }
}

}  // namespace
}  // namespace sf::test

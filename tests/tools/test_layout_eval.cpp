// evaluate-layouts (host/eval/layout_eval.hpp): its figures on hand-made frames, and the command on
// a tiny city.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "cli_runner.hpp"
#include "layout_eval.hpp"
#include "sf_test_env.hpp"

namespace {

namespace fs = std::filesystem;
using sf::eval::frame_metrics;

TEST(LayoutEval, EqualTexelSidesKeepTheTotal) {
  EXPECT_EQ(sf::eval::equal_texel_side(4096, 1), 4096);
  EXPECT_EQ(sf::eval::equal_texel_side(4096, 4), 2048);
  EXPECT_EQ(sf::eval::equal_texel_side(4096, 2), 2896);  // 4096 / sqrt 2 = 2896.3, a multiple of 8
  EXPECT_EQ(sf::eval::equal_texel_side(2048, 3), 1184);  // 1182.4 -> 1184
}

// Mismatches count where v and the hard reference fall on different sides of 1/2, over the mask;
// the near ones over the near mask; RMSE sums against both references.
TEST(LayoutEval, FrameMetricsCountMismatchesOverTheirMasks) {
  const std::vector<float> v{1.0f, 0.4f, 0.6f, 0.0f, 1.0f, 0.0f};
  const std::vector<float> hard{1.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f};
  const std::vector<float> soft{1.0f, 0.5f, 0.5f, 0.0f, 0.5f, 0.5f};
  const std::vector<uint8_t> mask{1, 1, 1, 1, 1, 0};  // the last receiver is not counted
  const std::vector<uint8_t> near{1, 1, 0, 0, 0, 0};
  const sf::eval::FrameMetrics m = frame_metrics(v, hard, soft, mask, near);
  EXPECT_EQ(m.counted, 5u);
  EXPECT_EQ(m.counted_near, 2u);
  EXPECT_EQ(m.mismatched, 3.0);       // receivers 1, 2 and 4
  EXPECT_EQ(m.mismatched_near, 1.0);  // receiver 1
  EXPECT_NEAR(m.sq_hard, 0.36 + 0.36 + 1.0, 1e-6);
  EXPECT_NEAR(m.sq_soft, 0.01 + 0.01 + 0.25, 1e-6);
}

TEST(LayoutEval, QuantilesAndMeanDifferences) {
  EXPECT_EQ(sf::eval::quantile({}, 0.5), 0.0);
  EXPECT_EQ(sf::eval::quantile({3, 1, 2, 5, 4}, 0.5), 3.0);
  EXPECT_EQ(sf::eval::quantile({3, 1, 2, 5, 4}, 0.0), 1.0);
  EXPECT_EQ(sf::eval::quantile({3, 1, 2, 5, 4}, 1.0), 5.0);
  EXPECT_NEAR(sf::eval::mean_abs_difference({0.0f, 1.0f, 0.5f}, {1.0f, 1.0f, 0.0f}, {1, 1, 0}), 0.5, 1e-9);
  EXPECT_EQ(sf::eval::mean_abs_difference({0.0f}, {1.0f}, {0}), 0.0);
}

// The command end to end on a tiny city: a row per layout and method with finite figures, a
// flicker figure from the second frame on, the CSV and Markdown files; bad options exit 2.
TEST(LayoutEvalCli, RunsEveryLayoutOnATinyCity) {
  const std::string dir = sf::test::temp_dir("layout_eval_cli");
  const std::string out = dir + "/out";
  const auto r = sf::test::run_cli("evaluate-layouts city -o " + out +
                                       " --total-size 128 --receivers 96x54 --frames 2 --samples 0 --runs 1 "
                                       "--methods pcf,esm --cascade-counts 2",
                                   dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out + "/results_layouts.csv"));
  EXPECT_TRUE(fs::exists(out + "/results_layouts.md"));
  const std::string csv = sf::test::slurp(out + "/results_layouts.csv");
  // Header + (single, pssm2, pssm2 unstable, tsm, pssm2+tsm) x 2 methods.
  EXPECT_EQ(sf::test::count_lines(csv), 11u) << csv;
  for (const char* layout : {"single,", "pssm2,", "pssm2 unstable,", "tsm,", "pssm2+tsm,"})
    EXPECT_NE(csv.find(std::string("city,") + layout), std::string::npos) << layout;
  EXPECT_EQ(csv.find("nan"), std::string::npos) << csv;
  EXPECT_NE(r.out.find("| city | pssm2 | pcf | 2 x 88² |"), std::string::npos) << r.out;

  for (const std::string& bad :
       {std::string("--layouts lispsm"), std::string("--cascade-counts 9"), std::string("--receivers 0x10"),
        std::string("--samples 3"), std::string("--methods nosuch"), std::string("--light-step 400")}) {
    const std::string bad_out = dir + "/bad";
    const auto b = sf::test::run_cli("evaluate-layouts city -o " + bad_out + " --total-size 64 --receivers 32x18 " +
                                         "--frames 1 --samples 0 --runs 1 " + bad,
                                     dir);
    EXPECT_EQ(b.exit_code, 2) << bad << ": " << b.err;
    EXPECT_EQ(sf::test::count_lines(b.err), 1u) << bad << ": " << b.err;
    EXPECT_FALSE(fs::exists(bad_out + "/results_layouts.csv")) << bad;
  }
  fs::remove_all(dir);
}

// Flicker at fixed world points: with the camera and the light still, every frame is the same and
// the flicker is 0; a light turning 2 degrees a frame moves the shadows and the error between
// method and reference changes with them (hard and soft methods on single and pssm), with the
// camera still and with it walking.
TEST(LayoutEval, FlickerUnderAMovingLight) {
  sf::eval::LayoutEvalRequest r;
  r.scenes = {"city"};
  r.layouts = {"single", "pssm"};
  r.cascade_counts = {2};
  r.unstabilized_too = false;
  r.methods = {"pcf", "ssmm"};
  r.total_size = 128;
  r.receivers_width = 96;
  r.receivers_height = 54;
  r.frames = 3;
  r.soft_samples = 4;
  r.timing_runs = 1;
  r.walk_step = 0.0;
  const auto still = sf::eval::evaluate_layouts(sf::test::runtime_ptr(), r);
  ASSERT_EQ(still.size(), 4u);
  // 0 up to float rounding: pssm's previous frame reads each receiver's view depth recomputed in
  // that frame's camera (the same camera), which may differ from the view file's in the last bit.
  for (const auto& row : still) EXPECT_LT(row.flicker, 1e-6) << row.layout << " " << row.method;
  r.light_step_degrees = 2.0;
  const auto moving = sf::eval::evaluate_layouts(sf::test::runtime_ptr(), r);
  r.walk_step = 2.0;  // metres a frame: the camera walks while the light turns
  const auto both = sf::eval::evaluate_layouts(sf::test::runtime_ptr(), r);
  ASSERT_EQ(moving.size(), 4u);
  ASSERT_EQ(both.size(), 4u);
  for (size_t k = 0; k < moving.size(); ++k) {
    std::printf("  %s %s: flicker still %.4f, light moving %.4f, light and camera %.4f; RMSE soft %.4f\n",
                moving[k].layout.c_str(), moving[k].method.c_str(), still[k].flicker, moving[k].flicker,
                both[k].flicker, moving[k].rmse_soft);
    for (const auto* row : {&moving[k], &both[k]}) {
      EXPECT_EQ(row->frames, 3) << row->layout << " " << row->method;
      EXPECT_GT(row->flicker, 1e-4) << row->layout << " " << row->method;
      EXPECT_LT(row->flicker, 0.5) << row->layout << " " << row->method;
      EXPECT_TRUE(std::isfinite(row->rmse_soft) && row->rmse_soft >= 0.0);
    }
  }
  // Rows: single pcf, single ssmm, pssm2 pcf, pssm2 ssmm. pssm's finer layers (2 x 128² over the
  // view's depth range) follow the moving shadows more closely than the single map (measured:
  // pcf 0.139 against 0.196, ssmm 0.105 against 0.207).
  EXPECT_LT(moving[2].flicker, moving[0].flicker * 0.9);
  EXPECT_LT(moving[3].flicker, moving[1].flicker * 0.9);
}

}  // namespace

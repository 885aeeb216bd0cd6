// evaluate --frames (host/eval/flicker.hpp): the flicker of a frame sequence by hand on three
// receivers, and the command on frames of a generated scene under a turning light: every
// configuration flickers a little, a sequence of one frame repeated not at all, and frames that
// are not one sequence are refused before anything runs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_runner.hpp"
#include "flicker.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

// Three receivers inside the map, all counted; the soft reference and one row given.
eval::Scene frame(const std::vector<float>& ref_soft) {
  Receivers rx;
  rx.width = 3;
  rx.height = 1;
  rx.u = {0.25f, 0.5f, 0.75f};
  rx.v = {0.5f, 0.5f, 0.5f};
  rx.d = {0.5f, 0.5f, 0.5f};
  eval::Scene s = eval::make_scene("frame", HostImage(4, 4, 1, 1.0f), rx);
  s.ref_soft = HostImage(3, 1, 1);
  s.ref_soft.data = ref_soft;
  return s;
}
eval::Row row(const std::vector<float>& v, double rmse) {
  eval::Row r;
  r.method = "pcf";
  r.label = "pcf R=1";
  r.visibility = v;
  r.soft.valid = true;
  r.soft.rmse = rmse;
  r.time_ms = 2.0;
  return r;
}

// e_0 = (0, 0, -1), e_1 = (0.2, 0.5, -1), e_2 = e_1: flicker (0.2 + 0.5 + 0) / 3 over the first
// pair, 0 over the second, 0.7 / 6 over the sequence; the RMSE the mean of the rows'.
TEST(EvalFrames, FlickerByHand) {
  eval::FlickerTracker t;
  t.add_frame(frame({0.5f, 1.0f, 1.0f}), {row({0.5f, 1.0f, 0.0f}, 0.1)});
  t.add_frame(frame({0.5f, 0.5f, 1.0f}), {row({0.7f, 1.0f, 0.0f}, 0.2)});
  t.add_frame(frame({0.5f, 0.5f, 1.0f}), {row({0.7f, 1.0f, 0.0f}, 0.3)});
  const auto rows = t.rows();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].frames, 3);
  EXPECT_NEAR(rows[0].flicker, 0.7 / 6.0, 1e-7);
  EXPECT_NEAR(rows[0].rmse, 0.2, 1e-12);
  EXPECT_EQ(rows[0].time_ms, 2.0);
  EXPECT_STREQ(t.reference(), "soft");
  // A frame of another size is no frame of this sequence.
  eval::Scene wide = frame({0.5f, 0.5f, 1.0f});
  wide.receivers.width = 4;
  EXPECT_THROW(t.add_frame(wide, {}), InputError);
}

class EvalFramesCli : public ::testing::Test {
 protected:
  // backyard at 64², 48x36 receivers, 4 light samples, its light turned `degrees` about the up
  // axis from the scene's default direction (0.35, -1, 0.25).
  void make_frame(const std::string& dir, double degrees, const std::string& extra = "",
                  const std::string& receivers = "48x36") {
    const double a = degrees * 3.14159265358979 / 180.0, x = 0.35, z = 0.25;
    std::ostringstream light;
    light.precision(9);
    light << x * std::cos(a) + z * std::sin(a) << ",-1," << -x * std::sin(a) + z * std::cos(a);
    const RunResult r = run_cli("scene backyard -o " + dir + " --size 64 --receivers " + receivers +
                                    " --samples 4 -q --light-dir " + light.str() + extra,
                                dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  // A directory of the test's own (ctest runs the tests side by side).
  void SetUp() override {
    dir_ = temp_dir(std::string("eval_frames_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (int k = 0; k < 3; ++k) make_frame(dir_ + "/f" + std::to_string(k), 2.0 * k);
  }
  std::string evaluate(const std::string& dirs, const std::string& out, int expect) {
    const RunResult r = run_cli("evaluate " + dirs +
                                    " --frames --methods pcf,vsm,ssmm --grid quick --runs 1 --warmup 0 "
                                    "--no-images -q -o " +
                                    out,
                                dir_);
    EXPECT_EQ(r.exit_code, expect) << r.err;
    if (expect == 2) {
      EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    }
    return expect == 2 ? r.err : slurp(out + "/results_frames.csv");
  }
  // Lines of results_frames.csv after the header: (flicker, frames) per configuration.
  static std::vector<std::pair<double, int>> flickers(const std::string& csv) {
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "method,config,frames,rmse_soft,flicker_soft,time_ms");
    std::vector<std::pair<double, int>> out;
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      for (size_t a = 0, b; (b = line.find(',', a)) != std::string::npos; a = b + 1) f.push_back(line.substr(a, b - a));
      out.emplace_back(std::stod(f[4]), std::stoi(f[2]));
    }
    return out;
  }
  std::string dir_;
};

TEST_F(EvalFramesCli, ATurningLightFlickersARepeatedFrameDoesNot) {
  const std::string frames = dir_ + "/f0 " + dir_ + "/f1 " + dir_ + "/f2";
  const auto moving = flickers(evaluate(frames, dir_ + "/moving", 0));
  ASSERT_GE(moving.size(), 5u);  // pcf R=1, R=3, vsm x 4, ssmm
  for (const auto& [flicker, count] : moving) {
    EXPECT_EQ(count, 3);
    EXPECT_GT(flicker, 1e-4);
    EXPECT_LT(flicker, 0.2);
  }
  const auto still = flickers(evaluate(dir_ + "/f1 " + dir_ + "/f1 " + dir_ + "/f1", dir_ + "/still", 0));
  ASSERT_EQ(still.size(), moving.size());
  for (const auto& [flicker, count] : still) EXPECT_EQ(flicker, 0.0);
  EXPECT_TRUE(fs::exists(dir_ + "/still/results_frames.md"));
}

TEST_F(EvalFramesCli, FramesThatAreNotOneSequenceAreRefused) {
  EXPECT_NE(evaluate(dir_ + "/f0", dir_ + "/one", 2).find("at least two"), std::string::npos);
  make_frame(dir_ + "/small", 4.0, "", "40x30");
  EXPECT_NE(evaluate(dir_ + "/f0 " + dir_ + "/small", dir_ + "/sized", 2).find("share one camera"), std::string::npos);
  make_frame(dir_ + "/moved", 4.0, " --camera-pos 9,4,9");
  EXPECT_NE(evaluate(dir_ + "/f0 " + dir_ + "/moved", dir_ + "/moved_out", 2).find("other world points"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ + "/moved_out/results.csv"));
  EXPECT_FALSE(fs::exists(dir_ + "/moved_out/results_frames.csv"));
}

}  // namespace
}  // namespace sf::test

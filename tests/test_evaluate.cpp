// host/eval: error statistics, the grid, the Pareto front, --auto, and `shadowfilter evaluate`
// end to end on a small synthetic scene directory.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "evaluate.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

// Hand-computed: errors 0, 0.01, 0.1, -0.2 over 4 valid receivers (the 5th masked out).
TEST(EvalErrors, StatisticsByHand) {
  const std::vector<float> v{0.5f, 0.51f, 0.6f, 0.3f, 0.0f};
  const std::vector<double> ref{0.5, 0.5, 0.5, 0.5, 1.0};
  const std::vector<uint8_t> mask{1, 1, 1, 1, 0};
  const eval::ErrorStats e = eval::error_stats(v, ref, mask);
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.n, 4u);
  EXPECT_NEAR(e.rmse, std::sqrt((0.0001 + 0.01 + 0.04) / 4), 1e-6);
  EXPECT_NEAR(e.max, 0.2, 1e-6);
  EXPECT_NEAR(e.p99, 0.2, 1e-6);  // ceil(0.99 * 4) = 4th smallest
  EXPECT_DOUBLE_EQ(e.frac_1_255, 0.75);
  EXPECT_DOUBLE_EQ(e.frac_005, 0.5);
  EXPECT_DOUBLE_EQ(e.leak, 0.25);
  EXPECT_DOUBLE_EQ(e.darken, 0.25);
  // NaN counts as an error of 1 (never hidden).
  const eval::ErrorStats n = eval::error_stats({NAN}, {0.5}, {1});
  EXPECT_DOUBLE_EQ(n.max, 1.0);
  EXPECT_THROW(eval::check_metric("p98"), InputError);
}

TEST(EvalGrid, FootprintLookupsOnlyWhenNeeded) {
  const auto m = eval::parse_methods("esm,csm");
  auto has_mips = [](const std::vector<FilterOptions>& g) {
    for (const auto& o : g)
      if (o.lookup.kind != Lookup::Bilinear) return true;
    return false;
  };
  EXPECT_FALSE(has_mips(eval::make_grid(m, eval::Grid::Quick, 1.0)));
  EXPECT_TRUE(has_mips(eval::make_grid(m, eval::Grid::Quick, 3.0)));
  EXPECT_EQ(eval::parse_methods("all").size(), methods().size());
  EXPECT_THROW(eval::parse_methods("esm,nope"), InputError);
  EXPECT_THROW(eval::parse_grid("huge"), InputError);
}

TEST(EvalPareto, FrontIsFastestThenStrictlyBetter) {
  std::vector<eval::Row> rows(4);
  const double t[] = {1, 2, 3, 4}, e[] = {0.3, 0.4, 0.1, 0.1};
  for (int i = 0; i < 4; ++i) {
    rows[i].time_ms = t[i];
    rows[i].sref.p99 = e[i];
    rows[i].sref.valid = true;
  }
  EXPECT_EQ(eval::pareto_front(rows, "p99"), (std::vector<size_t>{0, 2}));
}

// A small scene: a raised square (z = 0.3) over a floor (z = 0.6), receivers on the floor.
eval::Scene small_scene() {
  HostImage depth(48, 48, 1, 0.6f);
  for (int y = 12; y < 36; ++y)
    for (int x = 12; x < 36; ++x) depth.at(x, y) = 0.3f;
  Receivers rx;
  rx.width = rx.height = 32;
  rx.has_footprint = true;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      rx.u.push_back((x + 0.5f) / 32);
      rx.v.push_back((y + 0.5f) / 32);
      rx.d.push_back(0.6f);
      rx.f.push_back(1.0f);
    }
  return eval::make_scene("small", depth, rx);
}

// --auto picks something under the bound, skips the mip pyramid (footprints 1), and its error
// claim matches an independent measurement against s_ref.
TEST(EvalAuto, ChoosesUnderTheBoundAndSkipsMips) {
  const eval::Scene s = small_scene();
  eval::AutoRequest req;
  req.max_error = 0.02;
  req.target.blur.radius = 2;
  req.target.lookup.kind = Lookup::Mips;
  req.methods = {"pcf", "esm", "vsm"};
  req.timing = {0, 1};
  const eval::AutoResult r = eval::choose_auto(runtime_ptr(), s, req);
  ASSERT_TRUE(r.found) << eval::describe(r);
  EXPECT_EQ(r.chosen.lookup.kind, Lookup::Bilinear) << "footprints are all 1: no pyramid";
  EXPECT_LE(r.chosen_row.sref.p99, 0.02);
  const std::string text = eval::describe(r);
  EXPECT_NE(text.find("skipped mip pyramid"), std::string::npos) << text;
  EXPECT_NE(text.find("chose"), std::string::npos) << text;
  // Independent check of the chosen configuration's error.
  const eval::Measured m = eval::measure(runtime_ptr(), r.chosen, s, {0, 1});
  const auto want = eval::s_ref_parallel(s.depth, req.target.blur, Lookup::Bilinear, s.receivers, req.sref_bias);
  EXPECT_LE(eval::error_stats(m.visibility, want, s.valid).p99, 0.02 + 1e-6);
  // The choice is the fastest of the tried configurations under the bound.
  for (const auto& row : r.tried)
    if (row.sref.p99 <= req.max_error) {
      EXPECT_LE(r.chosen_row.time_ms, row.time_ms) << row.label;
    }
  // A bound vsm cannot meet at the square's edges (ESM is exact on this two-depth scene: the
  // occluded texels weigh exp(-80 * 0.3)) still finds pcf, exact up to float rounding.
  req.max_error = 1e-5;
  req.methods = {"pcf", "vsm"};
  const eval::AutoResult exact = eval::choose_auto(runtime_ptr(), s, req);
  ASSERT_TRUE(exact.found);
  EXPECT_EQ(exact.chosen.method, "pcf");
}

// `shadowfilter evaluate` on a scene directory: CSV and JSON rows with the error columns, the
// Pareto plot, exit 0; a missing directory exits 2.
TEST(EvalCli, WritesResults) {
  const std::string dir = temp_dir("eval_cli");
  const std::string scene = dir + "/tiny";
  std::filesystem::create_directories(scene);
  const eval::Scene s = small_scene();
  io::write_image(scene + "/shadowmap.exr", s.depth);
  HostImage rx(32, 32, 4);
  rx.channel_names = {"u", "v", "d", "f"};
  for (size_t i = 0; i < 32 * 32; ++i) {
    rx.data[4 * i] = s.receivers.u[i];
    rx.data[4 * i + 1] = s.receivers.v[i];
    rx.data[4 * i + 2] = s.receivers.d[i];
    rx.data[4 * i + 3] = 1.0f;
  }
  io::write_image(scene + "/receivers.exr", rx);
  HostImage hard(32, 32, 1, 1.0f);
  io::write_image(scene + "/reference_hard.exr", hard);
  const std::string out = dir + "/out";
  const std::string cmd = std::string(SF_CLI_PATH) + " evaluate " + scene + " --methods sm,esm --grid quick --runs 1 -q -o " +
                          out + " > " + dir + "/log.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream csv(out + "/results.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_NE(header.find("sref_p99"), std::string::npos);
  EXPECT_NE(header.find("hard_rmse"), std::string::npos);
  int rows = 0;
  while (std::getline(csv, line)) rows += !line.empty();
  EXPECT_GE(rows, 5);  // sm + esm {40,80} x R {1,3} (x mips when footprints > 1)
  EXPECT_TRUE(std::filesystem::exists(out + "/results.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/pareto_tiny.png"));
  EXPECT_TRUE(std::filesystem::exists(out + "/error_tiny_esm.png"));
  const std::string bad = std::string(SF_CLI_PATH) + " evaluate " + dir + "/missing -o " + out + " > /dev/null 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
}

}  // namespace
}  // namespace sf::test

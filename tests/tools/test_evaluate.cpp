// host/eval: error statistics, the grid, the Pareto front, --auto, and `shadowfilter evaluate`
// end to end on a small synthetic scene directory and, with the soft methods, a generated one.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "cli_runner.hpp"
#include "evaluate.hpp"
#include "expect_input_error.hpp"
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

// Acne and leaks on a constructed 20x10 hard reference, lit for x < 10 and shadowed from x = 10
// on, 7x7 windows: lit inside are x <= 6 (70 receivers), shadowed inside x >= 13 (70); the band
// x = 7..12 is in neither class, whatever the output says there.
TEST(EvalAcneLeak, ConstructedImagesByHand) {
  HostImage hard(20, 10, 1, 0.0f);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) hard.at(x, y) = 1.0f;
  std::vector<float> v(hard.data.begin(), hard.data.end());
  v[2 * 20 + 2] = 0.0f;    // acne
  v[5 * 20 + 3] = 0.49f;   // acne (below 0.5)
  v[6 * 20 + 4] = 0.5f;    // not acne (0.5 is not below 0.5)
  v[5 * 20 + 8] = 0.0f;    // in the band: not counted
  v[5 * 20 + 11] = 1.0f;   // in the band: not counted
  v[5 * 20 + 15] = 0.51f;  // leak
  v[0 * 20 + 19] = NAN;    // NaN: a leak
  std::vector<uint8_t> all(v.size(), 1);
  eval::AcneLeak a = eval::acne_leak(v, hard, all);
  ASSERT_TRUE(a.valid);
  EXPECT_EQ(a.lit, 70u);
  EXPECT_EQ(a.shadowed, 70u);
  EXPECT_DOUBLE_EQ(a.acne, 2.0 / 70.0);
  EXPECT_DOUBLE_EQ(a.leak, 2.0 / 70.0);

  // Receivers left out (facing away, misses) are in no window and counted in no class: with
  // x = 10..12 out, lit inside reaches x = 9 (100 receivers) and the wrong outputs there vanish.
  std::vector<uint8_t> mask = all;
  for (int y = 0; y < 10; ++y)
    for (int x = 10; x <= 12; ++x) mask[size_t(y) * 20 + x] = 0;
  a = eval::acne_leak(v, hard, mask);
  EXPECT_EQ(a.lit, 100u);
  EXPECT_EQ(a.shadowed, 70u);
  EXPECT_DOUBLE_EQ(a.acne, 3.0 / 100.0);  // (8, 5) now counts
  EXPECT_DOUBLE_EQ(a.leak, 2.0 / 70.0);

  // One shadowed receiver in a lit area takes its whole 7x7 neighbourhood out of the lit class;
  // the window is clipped at the image border (a corner receiver sees 4x4).
  HostImage lit(20, 20, 1, 1.0f);
  lit.at(10, 10) = 0.0f;
  a = eval::acne_leak(std::vector<float>(400, 1.0f), lit, std::vector<uint8_t>(400, 1));
  EXPECT_EQ(a.lit, 400u - 49u);
  EXPECT_EQ(a.shadowed, 0u);
  EXPECT_DOUBLE_EQ(a.leak, 0.0);  // no class, no fraction
  a = eval::acne_leak(std::vector<float>(400, 1.0f), lit, std::vector<uint8_t>(400, 1), 0);
  EXPECT_EQ(a.lit, 399u);  // radius 0: every receiver is its own class
  EXPECT_EQ(a.shadowed, 1u);
  EXPECT_DOUBLE_EQ(a.leak, 1.0);

  EXPECT_FALSE(eval::acne_leak(std::vector<float>(3, 1.0f), lit, std::vector<uint8_t>(3, 1)).valid);
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
  // Receivers with Jacobians: every footprint lookup of the default grid also runs isotropic,
  // labelled apart; none without them, and none in the quick grid.
  auto isotropic = [](const std::vector<FilterOptions>& g) {
    size_t n = 0, footprint = 0;
    for (const auto& o : g) {
      footprint += o.lookup.kind != Lookup::Bilinear && o.lookup.max_anisotropy > 1;
      if (o.lookup.max_anisotropy == 1) {
        ++n;
        EXPECT_NE(eval::config_label(o).find(" iso"), std::string::npos) << eval::config_label(o);
      }
    }
    return std::make_pair(n, footprint);
  };
  const auto [iso, aniso] = isotropic(eval::make_grid(m, eval::Grid::Default, 3.0, eval::kDefaultSrefBias, true));
  EXPECT_GT(iso, 0u);
  EXPECT_EQ(iso, aniso);
  EXPECT_EQ(isotropic(eval::make_grid(m, eval::Grid::Default, 3.0)).first, 0u);
  EXPECT_EQ(isotropic(eval::make_grid(m, eval::Grid::Quick, 3.0, eval::kDefaultSrefBias, true)).first, 0u);
  EXPECT_EQ(eval::parse_methods("all").size(), methods().size());
  EXPECT_THROW(eval::parse_methods("esm,nope"), InputError);
  EXPECT_THROW(eval::parse_grid("huge"), InputError);
}

// evaluate's method lists: the registry's methods and the soft ones, "soft" for the four, "all"
// for the registry's only; the soft grid per size.
TEST(EvalGrid, SoftMethodsBesideTheRegistry) {
  const eval::MethodLists both = eval::parse_evaluated_methods("esm,cssm,pcss,cssm");
  EXPECT_EQ(both.hard, std::vector<std::string>{"esm"});
  EXPECT_EQ(both.soft, (std::vector<SoftMethod>{SoftMethod::Cssm, SoftMethod::Pcss}));
  EXPECT_EQ(eval::parse_evaluated_methods("soft").soft.size(), 4u);
  EXPECT_TRUE(eval::parse_evaluated_methods("soft").hard.empty());
  EXPECT_EQ(eval::parse_evaluated_methods("all").hard.size(), methods().size());
  EXPECT_TRUE(eval::parse_evaluated_methods("all").soft.empty());
  expect_input_error([] { eval::parse_evaluated_methods("esm,nope"); },
                     {"unknown method 'nope'", "the soft methods pcss, cssm, ssmm, ssmm-improved"});
  expect_input_error([] { eval::parse_evaluated_methods(","); }, {"names no method"});
  const std::vector<SoftMethod> all{SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved};
  // quick: pcss, cssm M=4 mips and sat, ssmm n=4, ssmm-improved n=4; default: cssm M=8 and 16
  // mips, ssmm n=3 and 6, ssmm-improved n=3 more; wide: cssm M=8 and 16 sat, ssmm-improved n=6.
  EXPECT_EQ(eval::make_soft_grid(all, eval::Grid::Quick).size(), 5u);
  EXPECT_EQ(eval::make_soft_grid(all, eval::Grid::Default).size(), 10u);
  EXPECT_EQ(eval::make_soft_grid(all, eval::Grid::Wide).size(), 13u);
  std::vector<std::string> labels;
  for (const SoftOptions& o : eval::make_soft_grid(all, eval::Grid::Quick)) labels.push_back(eval::soft_label(o));
  EXPECT_EQ(labels,
            (std::vector<std::string>{"pcss", "cssm M=4 mips", "cssm M=4 sat", "ssmm n=4", "ssmm-improved n=4"}));
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

// Receivers with ndl <= 0 face away from the light: left out of every figure against the
// ray-traced references (and of acne / leaks), kept in s_ref's; NaN ndl is unknown and counts.
TEST(EvalAcneLeak, FacingAwayReceiversLeaveTheTracedFigures) {
  eval::Scene s = small_scene();
  Receivers rx = s.receivers;
  rx.has_ndl = true;
  rx.ndl.assign(rx.count(), 0.7f);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 4; ++x) rx.ndl[size_t(y) * 32 + x] = x == 0 ? 0.0f : -0.3f;
    rx.ndl[size_t(y) * 32 + 4] = NAN;
  }
  s = eval::make_scene("facing", s.depth, rx);
  EXPECT_EQ(s.valid_count, 32u * 32u);
  EXPECT_EQ(s.traced_count, 32u * 28u);
  s.ref_hard = HostImage(32, 32, 1, 1.0f);  // all lit: the occluded square is "acne"
  s.ref_soft = s.ref_hard;
  eval::SrefCache sref(s);
  FilterOptions o;
  o.method = "sm";
  o.depth_test.bias = float(eval::kDefaultSrefBias);
  const eval::Row row = eval::evaluate_config(runtime_ptr(), s, o, sref, {0, 1});
  EXPECT_EQ(row.sref.n, 32u * 32u);
  EXPECT_EQ(row.hard.n, 32u * 28u);
  EXPECT_EQ(row.soft.n, 32u * 28u);
  ASSERT_TRUE(row.acne_leak.valid);
  EXPECT_EQ(row.acne_leak.lit, 32u * 28u);
  size_t dark = 0;  // the occluder's shadow on the counted receivers
  for (size_t i = 0; i < s.traced.size(); ++i) dark += s.traced[i] && row.visibility[i] < 0.5f;
  EXPECT_GT(dark, 100u);
  EXPECT_DOUBLE_EQ(row.acne_leak.acne, double(dark) / (32.0 * 28.0));
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
  // The choice is the fastest of the finalists (median over the interleaved rounds of its time
  // over the round's fastest) up to the tie band: at least the requested tolerance, wider when
  // the rounds measured noise. Every finalist met the bound.
  EXPECT_GE(r.tolerance, req.time_tolerance);
  ASSERT_FALSE(r.finalists.empty());
  for (const auto& f : r.finalists) {
    EXPECT_GE(f.score, 1.0) << f.label;
    EXPECT_LE(r.chosen_score, (1.0 + r.tolerance) * f.score) << f.label;
    const auto row =
        std::find_if(r.tried.begin(), r.tried.end(), [&](const eval::Row& t) { return t.label == f.label; });
    ASSERT_NE(row, r.tried.end());
    EXPECT_LE(row->sref.p99, req.max_error) << f.label;
  }
  // A bound vsm cannot meet at the square's edges (ESM is exact on this two-depth scene: the
  // occluded texels weigh exp(-80 * 0.3)) still finds pcf, exact up to float rounding.
  req.max_error = 1e-5;
  req.methods = {"pcf", "vsm"};
  const eval::AutoResult exact = eval::choose_auto(runtime_ptr(), s, req);
  ASSERT_TRUE(exact.found);
  EXPECT_EQ(exact.chosen.method, "pcf");
}

// The bundled spheres scene: camera receivers (footprints up to ~90 texels) or the planar
// receiver_depth grid (every footprint 1).
eval::Scene spheres(bool planar) {
  HostImage depth = io::load_depth_map(data_path("spheres/shadowmap.exr"), {});
  const int w = depth.width, h = depth.height;
  Receivers rx = planar ? io::load_receiver_depth(data_path("spheres/receiver_depth.exr"), w, h, {})
                        : io::load_receiver_image(data_path("spheres/receivers.exr"));
  return eval::make_scene(planar ? "spheres_planar" : "spheres", std::move(depth), std::move(rx));
}

eval::AutoRequest spheres_request(double max_error, const std::string& metric = "p99") {
  eval::AutoRequest req;
  req.max_error = max_error;
  req.metric = metric;
  req.target.blur.radius = 3;
  req.lookup_from_scene = true;
  req.methods = {"sm", "pcf", "vsm", "msm"};
  req.timing = {0, 1};
  return req;
}

// Footprints all <= 1 (the planar receivers): no mip pyramid anywhere, even when asked for.
TEST(EvalAuto, BundledPlanarSceneGetsNoMips) {
  const eval::Scene s = spheres(true);
  ASSERT_LE(s.max_footprint, 1.0);
  eval::AutoRequest req = spheres_request(0.3);
  req.lookup_from_scene = false;
  req.target.lookup.kind = Lookup::Mips;
  const eval::AutoResult r = eval::choose_auto(runtime_ptr(), s, req);
  EXPECT_EQ(r.target.lookup.kind, Lookup::Bilinear);
  ASSERT_FALSE(r.tried.empty());
  for (const auto& row : r.tried) EXPECT_EQ(row.options.lookup.kind, Lookup::Bilinear) << row.label;
  for (const auto& c : r.not_tried) EXPECT_EQ(c.options.lookup.kind, Lookup::Bilinear);
  const std::string text = eval::describe(r);
  EXPECT_NE(text.find("skipped mip pyramid: every footprint is <= 1"), std::string::npos) << text;
  EXPECT_NE(text.find("skipped z-max pyramid"), std::string::npos) << text;
  // The camera receivers do need footprint weights: mips candidates exist there.
  const eval::Scene cam = spheres(false);
  EXPECT_GT(cam.max_footprint, 1.0);
  FilterOptions target;
  target.blur.radius = 3;
  target.lookup.kind = Lookup::Mips;
  const auto cands = eval::auto_candidates(cam, spheres_request(0.3), target, nullptr);
  EXPECT_TRUE(std::any_of(cands.begin(), cands.end(),
                          [](const eval::AutoCandidate& c) { return c.options.lookup.kind == Lookup::Mips; }));
  // Cost order: the smallest csm order and the narrowest storage come first.
  eval::AutoRequest csm = spheres_request(0.3);
  csm.methods = {"csm"};
  const auto cc = eval::auto_candidates(cam, csm, target, nullptr);
  ASSERT_FALSE(cc.empty());
  EXPECT_EQ(cc.front().options.csm.order, 1);
  EXPECT_EQ(cc.front().options.storage, Storage::Unorm8);
  for (size_t i = 1; i < cc.size(); ++i) EXPECT_LE(cc[i - 1].cost, cc[i].cost);
}

// A tight bound picks a more accurate (and costlier) configuration than a loose one; each choice
// meets its bound when measured independently.
TEST(EvalAuto, TightBoundPicksMoreAccurateThanLoose) {
  const eval::Scene s = spheres(false);
  const eval::AutoResult loose = eval::choose_auto(runtime_ptr(), s, spheres_request(1.0));
  const eval::AutoResult tight = eval::choose_auto(runtime_ptr(), s, spheres_request(0.2));
  ASSERT_TRUE(loose.found) << eval::describe(loose);
  ASSERT_TRUE(tight.found) << eval::describe(tight);
  EXPECT_EQ(tight.target.lookup.kind, Lookup::Mips);  // camera footprints > 1
  EXPECT_LE(tight.chosen_row.sref.p99, 0.2);
  EXPECT_GT(loose.chosen_row.sref.p99, 0.2) << "the loose bound should stop at a cheap, inaccurate method";
  EXPECT_LT(tight.chosen_row.sref.p99, loose.chosen_row.sref.p99);
  // Cheaper candidates than the tight choice's first hit were tried and missed the bound.
  EXPECT_GT(tight.tried.size(), loose.tried.size());
  const eval::Measured m = eval::measure(runtime_ptr(), tight.chosen, s, {0, 1});
  BlurOptions blur;
  blur.radius = 3;
  const auto want = eval::s_ref_parallel(s.depth, blur, Lookup::Mips, s.receivers, eval::kDefaultSrefBias);
  EXPECT_LE(eval::error_stats(m.visibility, want, s.valid).p99, 0.2 + 1e-6);
}

// The decision among the finalists from constructed times (choose_by_times, what choose_auto
// decides after its interleaved rounds): a score is the median over the rounds of a finalist's
// time over the round's fastest; within the tie band the lowest estimate wins.
TEST(EvalAuto, DecisionFromTimes) {
  // A clear winner wins though it has the highest estimate: B is 30% slower, outside the band.
  const std::vector<std::vector<double>> clear(5, {10.0, 13.0, 20.0});
  eval::TimedChoice c = eval::choose_by_times(clear, {3, 1, 2}, 0.05);
  EXPECT_EQ(c.pick, 0u);
  EXPECT_EQ(c.order, (std::vector<size_t>{0, 1, 2}));
  EXPECT_DOUBLE_EQ(c.score[1], 1.3);
  EXPECT_DOUBLE_EQ(c.score[2], 2.0);
  EXPECT_DOUBLE_EQ(c.noise, 0.0);
  EXPECT_DOUBLE_EQ(c.tolerance, 0.05);
  // A tie within the band (3% < 5%) goes to the cheaper estimate, whichever it is.
  const std::vector<std::vector<double>> tie(5, {10.0, 10.3});
  c = eval::choose_by_times(tie, {2, 1}, 0.05);
  EXPECT_EQ(c.order.front(), 0u);
  EXPECT_EQ(c.pick, 1u);
  EXPECT_EQ(eval::choose_by_times(tie, {1, 2}, 0.05).pick, 0u);
  EXPECT_EQ(eval::choose_by_times(tie, {2, 1}, 0.02).pick, 0u) << "3% is outside a 2% band";
  // Noise in one round does not flip it: a hiccup making A 4x slower, or a quiet moment making
  // B twice as fast, in one of five rounds; B is the cheaper estimate both times.
  std::vector<std::vector<double>> hiccup(5, {10.0, 13.0}), quiet = hiccup;
  hiccup[2][0] = 40.0;
  quiet[3][1] = 5.0;
  for (const auto& rounds : {hiccup, quiet}) {
    c = eval::choose_by_times(rounds, {2, 1}, 0.05);
    EXPECT_EQ(c.pick, 0u);
    EXPECT_DOUBLE_EQ(c.score[0], 1.0);
    EXPECT_DOUBLE_EQ(c.score[1], 1.3);
    EXPECT_LT(c.tolerance, 0.3);
    // Where a finalist stands in the list does not matter.
    std::vector<std::vector<double>> swapped;
    for (const auto& r : rounds) swapped.push_back({r[1], r[0]});
    EXPECT_EQ(eval::choose_by_times(swapped, {1, 2}, 0.05).pick, 1u);
  }
  // Measured noise widens the band past time_tolerance: ratios per round A 1, 1.05, 1; B 1.04, 1,
  // 1.04; C and D 1.1, 1.1, 1. Noise (score / least ratio - 1) 0, 0.04, 0.1, 0.1: median 0.07,
  // so B (4% slower, cheapest in the band) wins; C and D (10%) stay outside though cheaper.
  const std::vector<std::vector<double>> noisy{
      {10.0, 10.4, 11.0, 11.0}, {10.5, 10.0, 11.0, 11.0}, {10.0, 10.4, 10.0, 10.0}};
  c = eval::choose_by_times(noisy, {4, 1, 0.5, 0.5}, 0.01);
  EXPECT_NEAR(c.noise, 0.07, 1e-12);
  EXPECT_NEAR(c.tolerance, 0.07, 1e-12);
  EXPECT_EQ(c.order.front(), 0u);
  EXPECT_EQ(c.pick, 1u);
  EXPECT_EQ(eval::choose_by_times(noisy, {4, 1, 0.5, 0.5}, 0.0).pick, 1u);
  EXPECT_EQ(eval::choose_by_times(noisy, {4, 1, 0.5, 0.5}, 0.2).pick, 2u) << "a 20% band takes in C";
  // One finalist (or the first pass only): it is the choice; no noise to measure.
  c = eval::choose_by_times({{7.0}}, {1}, 0.05);
  EXPECT_EQ(c.pick, 0u);
  EXPECT_DOUBLE_EQ(c.score[0], 1.0);
  EXPECT_DOUBLE_EQ(c.noise, 0.0);
  EXPECT_DOUBLE_EQ(c.tolerance, 0.05);
  EXPECT_THROW(eval::choose_by_times({}, {1}, 0.05), InputError);
  EXPECT_THROW(eval::choose_by_times({{1.0, 2.0}, {1.0}}, {1, 2}, 0.05), InputError);
}

// choose_auto end to end with the CLI's timing: only what does not depend on the machine's
// timing (which finalist wins is DecisionFromTimes' job).
TEST(EvalAuto, RoundsChooseAFinalistUnderTheBound) {
  const eval::Scene s = spheres(false);
  eval::AutoRequest req = spheres_request(0.2);
  req.timing = {1, 3};  // the CLI's defaults
  const eval::AutoResult a = eval::choose_auto(runtime_ptr(), s, req);
  ASSERT_TRUE(a.found) << eval::describe(a);
  EXPECT_LE(a.chosen_row.sref.p99, 0.2);
  ASSERT_FALSE(a.finalists.empty());
  EXPECT_TRUE(std::any_of(a.finalists.begin(), a.finalists.end(),
                          [&](const auto& f) { return f.label == a.chosen_row.label; }));
  const int rounds = a.finalists.size() > 1 ? req.final_rounds : 0;
  EXPECT_EQ(a.chosen_row.runs, req.timing.runs * (1 + rounds)) << "the first pass and every final round";
  EXPECT_GE(a.tolerance, req.time_tolerance);
}

// --metric: the bound applies to the named metric (rmse here), not p99.
TEST(EvalAuto, MetricNamesTheBound) {
  const eval::Scene s = spheres(false);
  const eval::AutoResult by_rmse = eval::choose_auto(runtime_ptr(), s, spheres_request(0.12, "rmse"));
  const eval::AutoResult by_p99 = eval::choose_auto(runtime_ptr(), s, spheres_request(0.12, "p99"));
  ASSERT_TRUE(by_rmse.found) << eval::describe(by_rmse, "rmse");
  ASSERT_TRUE(by_p99.found) << eval::describe(by_p99);
  EXPECT_LE(by_rmse.chosen_row.sref.rmse, 0.12);
  EXPECT_GT(by_rmse.chosen_row.sref.p99, 0.12) << "rmse <= 0.12 admits configurations whose p99 is larger";
  EXPECT_LE(by_p99.chosen_row.sref.p99, 0.12);
  EXPECT_NE(by_rmse.chosen_row.label, by_p99.chosen_row.label);
  EXPECT_NE(eval::describe(by_rmse, "rmse").find("rmse"), std::string::npos);
  eval::AutoRequest bad = spheres_request(0.1, "p98");
  EXPECT_THROW(eval::choose_auto(runtime_ptr(), s, bad), InputError);
}

// `shadowfilter evaluate` on a scene directory: CSV and JSON rows with the error columns against
// every reference, the Pareto plots (the default one against the ray-traced soft shadow, here the
// target for lack of one, with a note) and the contact sheet, exit 0; bad options exit 2.
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
  const RunResult run = run_cli("evaluate " + scene +
                                    " --methods sm,esm --grid quick --runs 1 -q --target-blur-radius 1 "
                                    "--target-lookup bilinear -o " +
                                    out,
                                dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream csv(out + "/results.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_NE(header.find(",self_rmse,self_p99,"), std::string::npos) << header;
  EXPECT_NE(header.find("hard_rmse"), std::string::npos);
  EXPECT_NE(header.find(",acne,umbra_leak,lit_inside,shadowed_inside,target_filter,target_rmse,target_p99,"),
            std::string::npos)
      << header;
  EXPECT_EQ(header.find("sref_"), std::string::npos) << "the self columns were renamed";
  int rows = 0;
  while (std::getline(csv, line)) {
    if (line.empty()) continue;
    ++rows;
    EXPECT_NE(line.find(",\"R=1 bilinear\","), std::string::npos) << line;  // the target filter, on every row
  }
  EXPECT_GE(rows, 5);  // sm + esm {40,80} x R {1,3} (x mips when footprints > 1)
  EXPECT_TRUE(std::filesystem::exists(out + "/results.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/error_tiny_esm.png"));
  // No reference_soft.exr: the default plot is against the target, and says so on stderr and in
  // the plot; hard and self get their own plots; no soft one.
  for (const char* f : {"pareto_tiny.png", "pareto_tiny_hard.png", "pareto_tiny_self.png", "contact_tiny.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  for (const char* f : {"pareto_tiny_soft.png", "pareto_tiny_target.png"})
    EXPECT_FALSE(std::filesystem::exists(out + "/" + f)) << f;
  const std::string log_text = run.out + run.err;
  EXPECT_NE(log_text.find("scene 'tiny' has no reference_soft.exr: errors against the target filter's s_ref instead"),
            std::string::npos)
      << log_text;
  {
    auto in = OIIO::ImageInput::open(out + "/pareto_tiny.png");
    ASSERT_TRUE(in);
    const std::string d = in->spec().get_string_attribute("ImageDescription");
    EXPECT_NE(d.find("tiny: time vs RMSE against s_ref of the target filter R=1 bilinear"), std::string::npos) << d;
    EXPECT_NE(d.find("no reference_soft.exr"), std::string::npos) << d;
    in = OIIO::ImageInput::open(out + "/pareto_tiny_hard.png");
    ASSERT_TRUE(in);
    EXPECT_NE(in->spec().get_string_attribute("ImageDescription").find("against ray-traced hard shadow"),
              std::string::npos);
    in = OIIO::ImageInput::open(out + "/contact_tiny.png");
    ASSERT_TRUE(in);
    const eval::ContactLayout l = eval::contact_layout(32, 32, 3);  // the target, sm, esm
    EXPECT_EQ(in->spec().width, l.width);
    EXPECT_EQ(in->spec().height, l.height);
    EXPECT_EQ(in->spec().nchannels, 3);
  }
  // A prefixed metric names the reference (the older spelling); one that contradicts
  // --pareto-reference, an unknown reference and a radius that is no number exit 2.
  const std::string base = "evaluate " + scene + " --methods sm --runs 1 -q -o " + out;
  EXPECT_EQ(run_cli(base + " --pareto-metric hard_p99", dir).exit_code, 0);
  for (const char* bad_option : {"--pareto-metric hard_rmse --pareto-reference soft", "--pareto-reference ray",
                                 "--target-blur-radius nan", "--target-lookup trilinear", "--pareto-metric soft_p98"})
    EXPECT_EQ(run_cli(base + " " + bad_option, dir).exit_code, 2) << bad_option;
  // --auto with a named metric: auto.txt says what it chose under that metric.
  const std::string auto_out = dir + "/auto";
  const RunResult auto_run = run_cli("evaluate " + scene +
                                         " --methods sm,pcf,vsm --grid quick --runs 1 -q --auto --auto-radius 1"
                                         " --metric rmse --max-error 0.5 -o " +
                                         auto_out,
                                     dir);
  ASSERT_EQ(auto_run.exit_code, 0) << auto_run.err;
  std::ifstream auto_txt(auto_out + "/auto.txt");
  const std::string text((std::istreambuf_iterator<char>(auto_txt)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("auto: chose"), std::string::npos) << text;
  EXPECT_NE(text.find("rmse <= 0.5"), std::string::npos) << text;
  EXPECT_NE(text.find("skipped mip pyramid"), std::string::npos) << text;  // footprints 1
  EXPECT_EQ(run_cli("evaluate " + scene + " --auto --metric p98 -o " + auto_out, dir).exit_code, 2);
  EXPECT_EQ(run_cli("evaluate " + dir + "/missing -o " + out, dir).exit_code, 2);
  // The soft methods need the area light of the map's header, which this scene lacks: each is
  // skipped with the reason, and --auto takes no soft method.
  ASSERT_EQ(run_cli("evaluate " + scene + " --methods sm,pcss --grid quick --runs 1 -q -o " + out, dir).exit_code, 0);
  std::ifstream json(out + "/results.json");
  const std::string json_text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(json_text.find("\"config\": \"pcss\", \"reason\": \"the scene's shadow map names no area light"),
            std::string::npos)
      << json_text;
  const RunResult soft_auto = run_cli("evaluate " + scene + " --methods pcss --auto -o " + auto_out, dir);
  EXPECT_EQ(soft_auto.exit_code, 2);
  EXPECT_NE(soft_auto.err.find("--auto chooses among the non-soft methods"), std::string::npos) << soft_auto.err;
  // A light_size without the rest of the light: the soft methods are skipped saying what is
  // missing, the others run.
  HostImage half_lit = s.depth;
  half_lit.attributes = {{"light_size", "0.2"}};
  io::write_image(scene + "/shadowmap.exr", half_lit);
  ASSERT_EQ(run_cli("evaluate " + scene + " --methods sm,pcss --grid quick --runs 1 -q -o " + out, dir).exit_code, 0);
  std::ifstream json2(out + "/results.json");
  const std::string json2_text((std::istreambuf_iterator<char>(json2)), std::istreambuf_iterator<char>());
  EXPECT_NE(json2_text.find("its light_size needs a header near"), std::string::npos) << json2_text;
  EXPECT_NE(json2_text.find("\"method\": \"sm\""), std::string::npos) << json2_text;
}

// The soft methods in evaluate (issue 32 part 3): a generated scene under a rectangular light,
// every soft method of the quick grid beside esm, errors against the ray-traced references of
// that light (no s_ref: self and target empty), the light's sides in the parameters, the rows
// in the plots' legend.
TEST(EvalCli, SoftMethodsAgainstTheRayTracedReferences) {
  const std::string dir = temp_dir("eval_soft");
  ASSERT_EQ(
      run_cli("scene spheres -o " + dir + "/sph --size 128 --receivers 96x72 --samples 16 --light-size 0.4,0.1 -q", dir)
          .exit_code,
      0);
  const std::string out = dir + "/out";
  const RunResult run = run_cli("evaluate " + dir + "/sph --methods esm,soft --grid quick --runs 1 -q -o " + out, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream csv(out + "/results.csv");
  std::string header, line;
  std::getline(csv, header);
  // Comma-separated fields, empty ones included (the config and parameters columns are quoted
  // and hold no comma here).
  auto split = [](const std::string& text) {
    std::vector<std::string> f;
    for (size_t a = 0;;) {
      const size_t b = text.find(',', a);
      f.push_back(text.substr(a, b == std::string::npos ? std::string::npos : b - a));
      if (b == std::string::npos) return f;
      a = b + 1;
    }
  };
  const std::vector<std::string> columns = split(header);
  auto column = [&](const char* name) {
    return size_t(std::find(columns.begin(), columns.end(), name) - columns.begin());
  };
  std::vector<std::string> soft_configs;
  double best_soft = 1, best_esm = 1;
  while (std::getline(csv, line)) {
    const std::vector<std::string> f = split(line);
    ASSERT_EQ(f.size(), columns.size()) << line;
    const std::string method = f[column("method")];
    const double soft_rmse = std::atof(f[column("soft_rmse")].c_str());
    EXPECT_GT(soft_rmse, 0.0) << line;
    EXPECT_LT(soft_rmse, 0.2) << line;
    EXPECT_FALSE(f[column("hard_rmse")].empty()) << line;
    if (method == "esm") {
      best_esm = std::min(best_esm, soft_rmse);
      continue;
    }
    soft_configs.push_back(f[column("config")]);
    best_soft = std::min(best_soft, soft_rmse);
    EXPECT_TRUE(f[column("self_rmse")].empty()) << line;
    EXPECT_TRUE(f[column("target_rmse")].empty()) << line;
    EXPECT_NE(f[column("parameters")].find("light_size=0.4 light_height=0.1"), std::string::npos) << line;
  }
  EXPECT_EQ(soft_configs, (std::vector<std::string>{"\"pcss\"", "\"cssm M=4 mips\"", "\"cssm M=4 sat\"", "\"ssmm n=4\"",
                                                    "\"ssmm-improved n=4\""}));
  // The soft methods model the area light; esm filters a footprint of the map.
  std::printf("  best soft RMSE against reference_soft: soft methods %.4f, esm %.4f\n", best_soft, best_esm);
  EXPECT_LT(best_soft, best_esm);
  for (const char* f : {"pareto_sph.png", "contact_sph.png", "results.json"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
}

}  // namespace
}  // namespace sf::test

// host/eval: the Pareto front against one reference on constructed points, the labels that name
// the reference (on the plot and in its file), and the contact sheet's layout and pixels.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "evaluate.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::test {
namespace {

// Brute force: i is on the front unless a j is no slower and no worse, and better in one.
std::vector<size_t> non_dominated(const std::vector<double>& t, const std::vector<double>& e) {
  std::vector<size_t> out;
  for (size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(e[i])) continue;
    bool dominated = false;
    for (size_t j = 0; j < t.size() && !dominated; ++j)
      dominated = std::isfinite(e[j]) && t[j] <= t[i] && e[j] <= e[i] && (t[j] < t[i] || e[j] < e[i]);
    if (!dominated) out.push_back(i);
  }
  return out;
}

// A constructed grid: 3 times x 3 errors in shuffled order, plus an exact duplicate of a front
// point, a point as fast as a front point but worse, one as good but slower, and a NaN.
TEST(ParetoFront, NonDominatedSetOnAConstructedGrid) {
  //                         0    1    2    3    4    5    6    7    8    9    10   11   12
  const std::vector<double> t{3.0, 1.0, 2.0, 1.0, 3.0, 2.0, 1.0, 2.0, 3.0, 2.0, 1.0, 4.0, 0.5};
  const std::vector<double> e{0.1, 0.3, 0.2, 0.5, 0.4, 0.4, 0.4, 0.3, 0.6, 0.2, 0.3, 0.1, NAN};
  // Fastest first: (1, 0.3) twice (1 and 10, a tie: both), (2, 0.2) twice (2 and 9), (3, 0.1).
  // (4, 0.1) is as good as (3, 0.1) but slower; (0.5, NaN) has no error and is on no front.
  const std::vector<size_t> want{1, 10, 2, 9, 0};
  EXPECT_EQ(eval::pareto_front(t, e), want);
  std::vector<size_t> brute = non_dominated(t, e), got = eval::pareto_front(t, e);
  std::sort(brute.begin(), brute.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, brute);
  using D = std::vector<double>;
  EXPECT_TRUE(eval::pareto_front(D{}, D{}).empty());
  EXPECT_EQ(eval::pareto_front(D{5.0}, D{0.7}), (std::vector<size_t>{0}));
  EXPECT_THROW(eval::pareto_front(D{1.0}, D{}), InputError);
}

// Rows measured against several references: the front follows the reference asked for. Against
// self, sm and pcf are exact (0) and the front is "fastest, then sm"; against the ray-traced soft
// shadow the prefiltered methods are closer and the front differs.
TEST(ParetoFront, FollowsTheReference) {
  struct Spec {
    const char* method;
    double time, self, soft, hard, target;
  };
  const Spec specs[] = {{"esm", 1.0, 0.07, 0.10, 0.12, 0.05},
                        {"sm", 1.5, 0.0, 0.075, 0.02, 0.09},
                        {"pcf", 4.0, 0.0, 0.073, 0.06, 0.04},
                        {"msm", 6.0, 0.04, 0.061, 0.08, 0.03},
                        {"msm", 9.0, 0.03, 0.058, 0.09, 0.03}};
  std::vector<eval::Row> rows;
  for (const Spec& s : specs) {
    eval::Row r;
    r.method = s.method;
    r.label = s.method;
    r.time_ms = s.time;
    for (auto [stats, v] : {std::pair{&r.sref, s.self}, {&r.soft, s.soft}, {&r.hard, s.hard}, {&r.target, s.target}}) {
      stats->valid = true;
      stats->rmse = v;
    }
    rows.push_back(r);
  }
  EXPECT_EQ(eval::pareto_front(rows, eval::Reference::Self, "rmse"), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(eval::pareto_front(rows, eval::Reference::Soft, "rmse"), (std::vector<size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(eval::pareto_front(rows, eval::Reference::Hard, "rmse"), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(eval::pareto_front(rows, eval::Reference::Target, "rmse"), (std::vector<size_t>{0, 2, 3}));
  // The prefixed names of --pareto-metric; a bare metric is self, as in the files before.
  EXPECT_EQ(eval::pareto_front(rows, "soft_rmse"), eval::pareto_front(rows, eval::Reference::Soft, "rmse"));
  EXPECT_EQ(eval::pareto_front(rows, "rmse"), eval::pareto_front(rows, eval::Reference::Self, "rmse"));
  EXPECT_DOUBLE_EQ(eval::row_metric(rows[3], "target_rmse"), 0.03);
  EXPECT_DOUBLE_EQ(eval::row_metric(rows[3], "sref_rmse"), 0.04);
  // Best per method against soft: msm's slower row (0.058 < 0.061); against target a tie of
  // msm's rows goes to the faster.
  EXPECT_EQ(eval::best_per_method(rows, eval::Reference::Soft, "rmse"), (std::vector<size_t>{0, 1, 2, 4}));
  EXPECT_EQ(eval::best_per_method(rows, eval::Reference::Target, "rmse"), (std::vector<size_t>{0, 1, 2, 3}));
  // A reference a row was not measured against keeps it off the front.
  rows[1].soft.valid = false;
  EXPECT_EQ(eval::pareto_front(rows, eval::Reference::Soft, "rmse"), (std::vector<size_t>{0, 2, 3, 4}));
  EXPECT_TRUE(std::isnan(eval::row_error(rows[1], eval::Reference::Soft, "rmse")));
}

TEST(ParetoFront, ReferenceNamesAndMetrics) {
  EXPECT_EQ(eval::parse_reference("soft"), eval::Reference::Soft);
  EXPECT_EQ(eval::parse_reference("self"), eval::Reference::Self);
  EXPECT_THROW(eval::parse_reference("ray"), InputError);
  std::string m;
  eval::Reference r = eval::Reference::Soft;
  EXPECT_TRUE(eval::split_metric("hard_p99", &m, &r));
  EXPECT_EQ(m, "p99");
  EXPECT_EQ(r, eval::Reference::Hard);
  EXPECT_TRUE(eval::split_metric("target_frac_005", &m, &r));
  EXPECT_EQ(m, "frac_005");
  EXPECT_EQ(r, eval::Reference::Target);
  EXPECT_FALSE(eval::split_metric("rmse", &m, &r));
  EXPECT_EQ(m, "rmse");
  EXPECT_EQ(eval::metric_text("rmse"), "RMSE");
  EXPECT_THROW(eval::metric_text("p98"), InputError);
}

// A scene of 40x20 grid receivers (no GPU needed): every receiver valid, the left 8 columns
// facing away from the light; the soft reference 0.5 on the left half, 1 on the right.
eval::Scene sheet_scene() {
  Receivers rx;
  rx.width = 40;
  rx.height = 20;
  rx.has_footprint = true;
  rx.has_ndl = true;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x) {
      rx.u.push_back((x + 0.5f) / 40);
      rx.v.push_back((y + 0.5f) / 20);
      rx.d.push_back(0.6f);
      rx.f.push_back(1.0f);
      rx.ndl.push_back(x < 8 ? -0.5f : 0.5f);
    }
  eval::Scene s = eval::make_scene("sheet", HostImage(8, 8, 1, 0.9f), rx);
  s.ref_soft = HostImage(40, 20, 1, 1.0f);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) s.ref_soft.at(x, y) = 0.5f;
  return s;
}

// The labels name the reference in the title and on the error axis, and say when a scene fell
// back to the target for lack of a ray-traced image.
TEST(ParetoPlot, LabelsNameTheReference) {
  const eval::Scene s = sheet_scene();
  eval::TargetFilter target;
  target.blur.radius = 2;
  target.lookup = Lookup::Sat;
  eval::PlotLabels l = eval::pareto_labels(s, 31, eval::Reference::Soft, "rmse", target);
  EXPECT_EQ(l.title, "sheet: time vs RMSE against ray-traced soft shadow (reference_soft.exr)");
  EXPECT_EQ(l.y_axis, "RMSE against ray-traced soft shadow (reference_soft.exr)");
  EXPECT_EQ(l.subtitle, "31 configurations; 640 receivers facing the light; box = Pareto front");
  l = eval::pareto_labels(s, 31, eval::Reference::Target, "p99", target);
  EXPECT_EQ(l.y_axis, "p99 |error| against s_ref of the target filter R=2 sat");
  EXPECT_NE(l.subtitle.find("800 receivers"), std::string::npos) << l.subtitle;
  l = eval::pareto_labels(s, 31, eval::Reference::Self, "rmse", target);
  EXPECT_EQ(l.y_axis, "RMSE against s_ref of each configuration's own filter (fidelity)");
  EXPECT_NE(l.subtitle.find("sm and pcf are 0 by definition"), std::string::npos);
  // No reference_hard in this scene: the plot falls back to the target and says so.
  std::string note;
  EXPECT_EQ(eval::plot_reference(s, eval::Reference::Soft, &note), eval::Reference::Soft);
  EXPECT_TRUE(note.empty());
  EXPECT_EQ(eval::plot_reference(s, eval::Reference::Hard, &note), eval::Reference::Target);
  EXPECT_EQ(note, "scene 'sheet' has no reference_hard.exr: errors against the target filter's s_ref instead");
  EXPECT_EQ(eval::contact_reference(s, eval::Reference::Self), eval::Reference::Soft);
  EXPECT_EQ(eval::contact_reference(s, eval::Reference::Hard), eval::Reference::Target);
}

struct Png {
  int width = 0, height = 0, channels = 0;
  OIIO::TypeDesc format;
  std::string description;
  std::vector<uint8_t> pixels;
  std::array<int, 3> at(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return {pixels[i], pixels[i + 1], pixels[i + 2]};
  }
};

Png read_png(const std::string& path) {
  Png p;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return p;
  const OIIO::ImageSpec& spec = in->spec();
  p.width = spec.width;
  p.height = spec.height;
  p.channels = spec.nchannels;
  p.format = spec.format;
  p.description = spec.get_string_attribute("ImageDescription");
  p.pixels.resize(size_t(p.width) * p.height * p.channels);
  if (!in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::UINT8, p.pixels.data())) p.pixels.clear();
  return p;
}

std::vector<eval::Row> sheet_rows(const eval::Scene& s) {
  const std::vector<float> ref(s.ref_soft.data.begin(), s.ref_soft.data.end());
  std::vector<eval::Row> rows(3);
  rows[0].method = rows[1].method = "esm";
  rows[2].method = "vsm";
  rows[0].label = "esm a";
  rows[1].label = "esm b";
  rows[2].label = "vsm";
  rows[0].visibility = rows[1].visibility = rows[2].visibility = ref;
  rows[1].visibility[5 * 40 + 25] = 1.0f + 0.3f;    // a leak of 0.3 at (25, 5): saturated red
  rows[1].visibility[5 * 40 + 26] = NAN;            // NaN: the worst error, saturated red
  for (float& v : rows[2].visibility) v -= 0.125f;  // darker by half the scale everywhere
  const double soft[] = {0.2, 0.1, 0.125};
  for (size_t i = 0; i < 3; ++i) {
    rows[i].time_ms = 1.0 + double(i);
    rows[i].soft.valid = true;
    rows[i].soft.rmse = soft[i];
  }
  return rows;
}

// The Pareto PNG decodes through OpenImageIO as 8-bit RGB with the plot's labels stored in it.
TEST(ParetoPlot, PngCarriesItsLabels) {
  const eval::Scene s = sheet_scene();
  const std::vector<eval::Row> rows = sheet_rows(s);
  const eval::PlotLabels labels = eval::pareto_labels(s, rows.size(), eval::Reference::Soft, "rmse", {});
  const std::string path = temp_dir("pareto_png") + "/pareto_sheet.png";
  eval::write_pareto_png(path, rows, eval::Reference::Soft, "rmse", labels);
  const Png p = read_png(path);
  EXPECT_EQ(p.width, 1200);
  EXPECT_EQ(p.height, 700);
  EXPECT_EQ(p.channels, 3);
  EXPECT_EQ(p.format, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(p.description, labels.description());
  EXPECT_NE(p.description.find("against ray-traced soft shadow (reference_soft.exr)"), std::string::npos);
  ASSERT_FALSE(p.pixels.empty());
  EXPECT_EQ(p.at(5, 690), (std::array<int, 3>{255, 255, 255}));  // the white margin
  // No temporary file is left beside it.
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
    files += entry.is_regular_file();
  EXPECT_EQ(files, 1u);
}

// The layout by hand, then a sheet's size and pixels: the reference tile shows the reference,
// each method's error map is red where it leaks, blue where it darkens, white where it agrees,
// and the receivers no figure counts are the background colour.
TEST(ContactSheet, LayoutAndPixels) {
  // 640x480 receivers, 10 cells: shrunk 1:2 to 320x240, 5 columns, 2 rows.
  eval::ContactLayout l = eval::contact_layout(640, 480, 10);
  EXPECT_EQ(l.shrink, 2);
  EXPECT_EQ(l.tile_w, 320);
  EXPECT_EQ(l.tile_h, 240);
  EXPECT_EQ(l.columns, 5);
  EXPECT_EQ(l.rows, 2);
  EXPECT_EQ(l.width, 10 + 5 * (320 + 10));                       // 1660
  EXPECT_EQ(l.height, 56 + 2 * (36 + 240 + 4 + 240 + 10) + 64);  // 1180
  EXPECT_EQ(eval::contact_layout(1920, 1080, 3).shrink, 6);
  EXPECT_EQ(eval::contact_layout(1920, 1080, 3).tile_h, 180);
  EXPECT_THROW(eval::contact_layout(640, 480, 0), InputError);

  const eval::Scene s = sheet_scene();
  const std::vector<eval::Row> rows = sheet_rows(s);
  const std::vector<size_t> best = eval::best_per_method(rows, eval::Reference::Soft, "rmse");
  ASSERT_EQ(best, (std::vector<size_t>{1, 2}));
  l = eval::contact_layout(40, 20, 3);
  EXPECT_EQ(l.shrink, 1);
  EXPECT_EQ(l.width, 10 + 3 * (260 + 10));                 // cells of the least width, 820
  EXPECT_EQ(l.height, 56 + (36 + 20 + 4 + 20 + 10) + 64);  // 210
  const std::string path = temp_dir("contact_sheet") + "/contact_sheet.png";
  eval::write_contact_sheet(path, s, rows, best, eval::Reference::Soft, "rmse", {}, {});
  const Png p = read_png(path);
  ASSERT_EQ(p.width, l.width);
  ASSERT_EQ(p.height, l.height);
  ASSERT_EQ(p.channels, 3);
  EXPECT_EQ(p.format, OIIO::TypeDesc::UINT8);
  ASSERT_FALSE(p.pixels.empty());
  EXPECT_NE(p.description.find("against ray-traced soft shadow (reference_soft.exr)"), std::string::npos);
  auto near = [](std::array<int, 3> got, std::array<int, 3> want) {
    for (int c = 0; c < 3; ++c)
      if (std::abs(got[c] - want[c]) > 1) return false;
    return true;
  };
  auto picture = [&](size_t cell, int x, int y) { return p.at(l.cell_x(cell) + x, l.cell_y(cell) + 36 + y); };
  auto error = [&](size_t cell, int x, int y) { return p.at(l.cell_x(cell) + x, l.cell_y(cell) + 36 + 20 + 4 + y); };
  const std::array<int, 3> background{140, 173, 140}, white{255, 255, 255};
  EXPECT_TRUE(near(picture(0, 12, 3), {128, 128, 128}));  // reference 0.5
  EXPECT_TRUE(near(picture(0, 30, 3), white));            // reference 1
  EXPECT_TRUE(near(picture(0, 3, 3), background));        // facing away: not counted
  EXPECT_TRUE(near(picture(1, 25, 5), white));            // 1.3 shown clamped to 1
  EXPECT_TRUE(near(error(1, 25, 5), {217, 26, 26}));      // +0.3: saturated red
  EXPECT_TRUE(near(error(1, 26, 5), {217, 26, 26}));      // NaN: the worst error
  EXPECT_TRUE(near(error(1, 30, 10), white));             // equal
  EXPECT_TRUE(near(error(1, 3, 10), background));
  EXPECT_TRUE(near(picture(2, 30, 10), {223, 223, 223}));  // 0.875
  EXPECT_TRUE(near(error(2, 30, 10), {140, 166, 242}));    // -0.125: half way to blue
  EXPECT_TRUE(near(error(2, 12, 10), {140, 166, 242}));
}

}  // namespace
}  // namespace sf::test

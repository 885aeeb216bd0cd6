// A method defined entirely in this file: its OpenCL header given as a string, its parameter
// declared in the registration and kept in FilterOptions::parameters. Registered through
// sf::register_method, it runs through the Pipeline against its double twin and through the
// CLI's generated flags, as a method of the library does.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "filter_options.hpp"
#include "finite_numbers.hpp"
#include "evaluate.hpp"
#include "method_catalogue.hpp"
#include "option_names.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// ramp: B = z; v = clamp(1 - k max(d - bar(B), 0), 0, 1), a shadow that deepens linearly with
// the receiver's depth behind the filtered occluder depth.
constexpr const char* kRampHeader = R"CLC(
#ifndef SF_TEST_RAMP_CLH_
#define SF_TEST_RAMP_CLH_
#define SF_CHANNELS 1
typedef struct {
  float k;
} sf_test_ramp_params;
typedef sf_test_ramp_params sf_method_params;
inline void sf_basis(float z, const sf_method_params P, float* b) { b[0] = z; }
inline void sf_basisv(sf_xfloat z, const sf_method_params P, sf_xfloat* b) { b[0] = z; }
inline float sf_visibility(const float* b, float d, const sf_method_params P) {
  return clamp(1.0f - P.k * fmax(d - b[0], 0.0f), 0.0f, 1.0f);
}
#endif
)CLC";

// The host's sf_test_ramp_params (the layout check of a one-float struct).
struct RampParams {
  float k;
};
static_assert(sizeof(RampParams) == 4, "sf_test_ramp_params is one float");

const Parameter& ramp_k() {
  static const Parameter p = Parameter::real("", "--test-ramp-k", "K", "test-ramp's slope k")
                                 .with_default(8)
                                 .within({0, 64})
                                 .stored("test_ramp.k");
  return p;
}

// How often the registry validated ramp's options (its validate counts).
std::atomic<int> ramp_validations{0};

// Registered once per process, on first use.
Method ramp() {
  static const Method m = [] {
    MethodDesc d;
    d.name = "test-ramp";
    d.summary = "a linear ramp behind the filtered depth (a test's method)";
    d.header = "test/ramp.clh";
    d.header_source = kRampHeader;
    d.channel_count = [](const FilterOptions&) { return 1; };
    d.parameters = {ramp_k()};
    d.storages = {{Storage::F32, "", {}}};
    d.validate = [](const FilterOptions& o) {
      ++ramp_validations;
      if (o.storage != Storage::F32) throw InputError("test-ramp stores f32 only");
    };
    d.pack_params = [](const FilterOptions& o) {
      const RampParams p{float(ramp_k().get(o))};
      std::vector<uint8_t> b(sizeof p);
      std::memcpy(b.data(), &p, sizeof p);
      return b;
    };
    d.scalar = [](const FilterOptions& o) {
      const double k = float(ramp_k().get(o));
      ScalarMethod s;
      s.basis = [](double z, double* b) { b[0] = z; };
      s.visibility = [k](const double* b, double dd) { return std::clamp(1 - k * std::max(dd - b[0], 0.0), 0.0, 1.0); };
      return s;
    };
    d.parameter_values = [](const FilterOptions& o) { return std::vector<MethodParameter>{{"k", ramp_k().get(o)}}; };
    return register_method(d);
  }();
  return m;
}

// A 24 x 16 map of two depth levels with a slanted edge, and receivers on its grid behind it.
HostImage ramp_map() {
  HostImage depth(24, 16);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) depth.at(x, y) = x + y / 2 < 12 ? 0.3f : 0.6f;
  return depth;
}

Receivers grid_behind(const HostImage& depth) {
  Receivers r;
  r.width = depth.width;
  r.height = depth.height;
  r.grid = true;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) r.d.push_back(0.35f + 0.01f * float(x % 7));
  return r;
}

TEST(MethodRegistration, TestMethodRunsThroughThePipelineAgainstItsTwin) {
  const HostImage depth = ramp_map();
  const Receivers rx = grid_behind(depth);
  std::vector<float> at_k[2];
  int run = 0;
  for (double k : {12.0, 2.0}) {
    FilterOptions o;
    o.method = ramp();
    o.blur.radius = 2;
    o.parameters["test_ramp.k"] = k;
    const FilterResult r = filter(runtime_ptr(), o, depth, rx);
    const std::vector<double> want = ref::filter(o, depth, rx);
    ASSERT_EQ(want.size(), r.visibility.data.size());
    double worst = 0;
    for (size_t i = 0; i < want.size(); ++i) worst = std::max(worst, std::abs(double(r.visibility.data[i]) - want[i]));
    // float32 blur weights and sums: 1e-6 in bar(B), times k.
    EXPECT_LE(worst, 2e-5 * k) << "k = " << k;
    at_k[run++] = r.visibility.data;
  }
  // The stored parameter reaches the kernel: k = 12 and k = 2 give different shadows.
  double apart = 0;
  for (size_t i = 0; i < at_k[0].size(); ++i) apart = std::max(apart, double(std::abs(at_k[0][i] - at_k[1][i])));
  EXPECT_GT(apart, 0.3);
}

// A plan validates its options once; the passes of its frames do not validate again.
TEST(MethodRegistration, FramesAreValidatedByTheirPlanOnly) {
  const HostImage depth = ramp_map();
  const Receivers rx = grid_behind(depth);
  FilterOptions o;
  o.method = ramp();
  o.blur.radius = 1;
  FrameFilter frames(runtime_ptr(), o);
  const int before = ramp_validations;
  for (int i = 0; i < 3; ++i) frames.run(depth, rx);
  EXPECT_EQ(ramp_validations - before, 1);  // the one plan of this map size
  const int one = ramp_validations;
  filter(runtime_ptr(), o, depth, rx);
  EXPECT_EQ(ramp_validations - one, 2);  // FrameFilter's check before any frame, and the plan
}

TEST(MethodRegistration, DeclaredRangeAndStoredKeysAreChecked) {
  FilterOptions o;
  o.method = ramp();
  o.parameters["test_ramp.k"] = 99;
  try {
    Pipeline::plan(runtime(), o, 8, 8);
    FAIL() << "k = 99 was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "FilterOptions::parameters.test_ramp.k must be in [0, 64], got 99");
  }
  o.parameters["test_ramp.k"] = NAN;
  EXPECT_THROW(Pipeline::plan(runtime(), o, 8, 8), InputError);
  o.parameters = {{"test_ramp.kk", 1.0}};
  try {
    Pipeline::plan(runtime(), o, 8, 8);
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "FilterOptions::parameters.test_ramp.kk is no registered method's parameter");
  }
}

// The CLI's flags come from the declarations: --method names the registered method, the
// generated --test-ramp-k sets its stored value, and bad values get the CLI's one-line messages.
TEST(MethodRegistration, TestMethodThroughTheCliOptionParser) {
  ramp();
  auto parse = [](std::vector<std::string> args, FilterOptions& o) {
    CLI::App app;
    cli::add_method_options(app, o);
    cli::add_prefilter_options(app, o);
    cli::require_finite_numbers(app);
    std::reverse(args.begin(), args.end());
    app.parse(args);
  };
  FilterOptions o;
  parse({"--method", "test-ramp", "--test-ramp-k", "3.5", "--blur-radius", "2"}, o);
  EXPECT_EQ(o.method, ramp());
  EXPECT_EQ(o.parameters.at("test_ramp.k"), 3.5);
  EXPECT_EQ(o.blur.radius, 2);

  FilterOptions bad;
  parse({"--method", "test-ramp", "--test-ramp-k", "70"}, bad);  // parsed; the range is the method's
  try {
    validate_options(bad);
    FAIL() << "k = 70 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(cli::cli_message(e.what()), "--test-ramp-k must be in [0, 64], got 70");
  }
  for (const char* text : {"nan", "abc"}) {
    FilterOptions o2;
    try {
      parse({"--test-ramp-k", text}, o2);
      ADD_FAILURE() << text << " was accepted";
    } catch (const CLI::ParseError& e) {
      EXPECT_NE(std::string(e.what()).find("--test-ramp-k"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  FilterOptions unknown;
  EXPECT_THROW(parse({"--method", "no-such-method"}, unknown), CLI::ValidationError);
}

// Evaluate's catalogue has no entry for it: the default one (its defaults only, the default cost).
TEST(MethodRegistration, TestMethodGetsTheCataloguesDefaultEntry) {
  FilterOptions base;
  base.method = ramp();
  EXPECT_FALSE(eval::catalogued(ramp()));
  EXPECT_EQ(eval::grid_variants(base, eval::Grid::Wide).size(), 1u);
  EXPECT_EQ(eval::auto_variants(base).size(), 1u);
  EXPECT_EQ(eval::catalogue_label(base), "");
  EXPECT_EQ(eval::catalogue_entry(ramp()).cost.reconstruct, eval::CostModel{}.reconstruct);
}

TEST(MethodRegistration, RefusesClashesAndMissingParts) {
  ramp();
  auto refused = [](MethodDesc d, const std::string& why) {
    try {
      register_method(std::move(d));
      ADD_FAILURE() << "registered: " << why;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  MethodDesc copy = *ramp();
  refused(copy, "a method of this name is registered");
  copy.name = "test-ramp-2";
  copy.header = "test/ramp-2.clh";
  copy.header_source.clear();
  refused(copy, "is not embedded and no header_source is given");
  copy.header = "methods/esm.clh";
  copy.header_source = kRampHeader;
  refused(copy, "would replace the embedded file");
  copy.header = "test/ramp-2.clh";
  copy.parameters = {ramp_k()};
  copy.parameters[0].flag = "--esm-c";
  refused(copy, "clashes with FilterOptions::esm.c");
  copy.parameters = {};
  copy.scalar = nullptr;
  refused(copy, "double-precision twin");
  EXPECT_EQ(
      std::count_if(methods().begin(), methods().end(), [](const MethodDesc& m) { return m.name == "test-ramp-2"; }),
      0);
}

}  // namespace
}  // namespace sf::test

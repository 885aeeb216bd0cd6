// FilterOptions: every floating-point field must be finite (require_finite_options), whatever
// the method reads: a NaN is never a default.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// Every floating-point field of FilterOptions must be finite, whatever the method reads.
TEST(FilterOptionsFinite, NonFiniteFieldsAreRefused) {
  const float bad[] = {NAN, INFINITY, -INFINITY};
  using Set = void (*)(FilterOptions&, float);
  const std::pair<const char*, Set> fields[] = {
      {"esm.c", [](FilterOptions& o, float v) { o.esm.c = v; }},
      {"depth_test.bias", [](FilterOptions& o, float v) { o.depth_test.bias = v; }},
      {"receiver_plane.max_slope", [](FilterOptions& o, float v) { o.receiver_plane.max_slope = v; }},
      {"vsm.min_variance", [](FilterOptions& o, float v) { o.vsm.min_variance = v; }},
      {"vsm.lbr", [](FilterOptions& o, float v) { o.vsm.lbr = v; }},
      {"evsm.pos", [](FilterOptions& o, float v) { o.evsm.pos = v; }},
      {"evsm.neg", [](FilterOptions& o, float v) { o.evsm.neg = v; }},
      {"msm.moment_bias", [](FilterOptions& o, float v) { o.msm.moment_bias = v; }},
      {"csm.alpha", [](FilterOptions& o, float v) { o.csm.alpha = v; }},
      {"csm.offset", [](FilterOptions& o, float v) { o.csm.offset = v; }},
      {"csm.scale", [](FilterOptions& o, float v) { o.csm.scale = v; }},
      {"blur.sigma", [](FilterOptions& o, float v) { o.blur.sigma = v; }},
      {"esm_classify.zmax_offset", [](FilterOptions& o, float v) { o.esm_classify.zmax_offset = v; }},
      {"esm_classify.threshold_eps", [](FilterOptions& o, float v) { o.esm_classify.threshold_eps = v; }},
  };
  for (const auto& [name, set] : fields)
    for (float v : bad) {
      FilterOptions o;  // esm: most of these fields are not its own
      set(o, v);
      try {
        Pipeline::plan(runtime(), o, 8, 8);
        ADD_FAILURE() << name << " = " << v << " was accepted";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(std::string("FilterOptions::") + name), std::string::npos) << e.what();
      }
    }
}

}  // namespace
}  // namespace sf::test

// Acne and leaks of every method with its defaults (the "before" table of docs/results.md;
// sf_measure, run by scripts/acne_leak.sh; not part of the test suite).
//   SF_ACNE_SCENES="dir dir ..." [SF_ACNE_RADIUS=2] sf_measure --gtest_filter='AcneLeak.*'
// Every scene dir is the scene tool's (shadowmap.exr with the light in its header, receivers.exr
// with ndl, reference_hard.exr, reference_soft.exr). Basis methods run with FilterOptions'
// defaults and --blur-radius SF_ACNE_RADIUS where the method follows the prefilter; soft methods
// with SoftOptions' defaults and the scene's light. Figures over the receivers facing the light
// (eval::Scene::traced); the last column counts every valid receiver, facing-away ones included.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "evaluate.hpp"
#include "scene_light.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::test {
namespace {

std::vector<std::string> scene_dirs() {
  std::vector<std::string> v;
  const char* e = std::getenv("SF_ACNE_SCENES");
  std::istringstream in(e ? e : "");
  std::string s;
  while (in >> s) v.push_back(s);
  return v;
}

std::vector<double> as_double(const HostImage& img) { return {img.data.begin(), img.data.end()}; }

void print_row(const eval::Scene& s, const std::string& label, const std::vector<float>& v) {
  const eval::AcneLeak al = eval::acne_leak(v, s.ref_hard, s.traced);
  const eval::AcneLeak all = eval::acne_leak(v, s.ref_hard, s.valid);
  const eval::ErrorStats soft = eval::error_stats(v, as_double(s.ref_soft), s.traced);
  const eval::ErrorStats hard = eval::error_stats(v, as_double(s.ref_hard), s.traced);
  std::printf("| %s | %s | %.2f | %.2f | %.3f | %.3f | %.2f / %.2f |\n", s.name.c_str(), label.c_str(), 100.0 * al.acne,
              100.0 * al.leak, soft.rmse, hard.rmse, 100.0 * all.acne, 100.0 * all.leak);
}

// The classes depend on the scene alone (the hard reference and which receivers count).
TEST(AcneLeak, Classes) {
  std::printf("| scene | valid receivers | facing the light | lit inside | shadowed inside |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const std::string& dir : scene_dirs()) {
    const eval::Scene s = eval::load_scene(dir);
    const eval::AcneLeak c = eval::acne_leak(s.ref_hard.data, s.ref_hard, s.traced);
    std::printf("| %s | %zu | %zu | %zu | %zu |\n", s.name.c_str(), s.valid_count, s.traced_count, c.lit, c.shadowed);
  }
}

TEST(AcneLeak, Defaults) {
  const char* r = std::getenv("SF_ACNE_RADIUS");
  const int radius = r ? std::atoi(r) : 2;
  std::printf("| scene | method | acne %% | leak %% | soft RMSE | hard RMSE | acne / leak %% incl. facing away |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const std::string& dir : scene_dirs()) {
    const eval::Scene s = eval::load_scene(dir);
    ASSERT_TRUE(s.receivers.has_ndl) << dir << ": receivers without ndl";
    ASSERT_EQ(s.ref_hard.texels(), s.receivers.count()) << dir;
    ASSERT_EQ(s.ref_soft.texels(), s.receivers.count()) << dir;
    for (const MethodDesc& m : methods()) {
      FilterOptions o;
      o.method = m.name;
      if (m.filtered) o.blur.radius = radius;
      const FilterResult f = filter(runtime_ptr(), o, s.depth, s.receivers);
      print_row(s, eval::config_label(o), f.visibility.data);
    }
    for (SoftMethod sm : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}) {
      SoftOptions o;
      o.method = sm;
      o.light = header_light(dir + "/shadowmap.exr");
      const SoftResult f = soft_filter(runtime_ptr(), o, s.depth, s.receivers);
      print_row(s, soft_method_name(sm), f.visibility.data);
    }
  }
}

}  // namespace
}  // namespace sf::test

// Anisotropic footprints on grazing floors (docs/lookups.md "Anisotropic footprints"; sf_measure,
// run by scripts/anisotropic_floor.sh; not part of the test suite).
//   SF_ANISO_SCENES="dir dir ..." [SF_ANISO_RADIUS=1] [SF_ANISO_RUNS=7] sf_measure --gtest_filter='Anisotropic.*'
// Every scene dir is the scene tool's, its receivers.exr with the Jacobian channels. Every
// filtered method (pcf and the basis methods, defaults otherwise), mips and sat, at
// max_anisotropy 1 (the isotropic lookup at f), 4, 8 and 16: RMSE against the ray-traced soft
// reference over the receivers facing the light, and the reconstruction's device time (median
// of SF_ANISO_RUNS, the configurations interleaved run by run on warm FrameFilters).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "evaluate.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::test {
namespace {

std::vector<std::string> scene_dirs() {
  std::vector<std::string> v;
  const char* e = std::getenv("SF_ANISO_SCENES");
  std::istringstream in(e ? e : "");
  std::string s;
  while (in >> s) v.push_back(s);
  return v;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

TEST(Anisotropic, GrazingFloors) {
  const int radius = std::getenv("SF_ANISO_RADIUS") ? std::atoi(std::getenv("SF_ANISO_RADIUS")) : 1;
  const int runs = std::getenv("SF_ANISO_RUNS") ? std::atoi(std::getenv("SF_ANISO_RUNS")) : 7;
  const int caps[] = {1, 4, 8, 16};
  std::printf(
      "| scene | method | lookup | soft RMSE, isotropic | 4 | 8 | 16 | RMSE change at 4 / 8 | reconstruction ms, "
      "isotropic | time ratio at 4 / 8 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& dir : scene_dirs()) {
    const eval::Scene s = eval::load_scene(dir);
    ASSERT_TRUE(s.receivers.has_jacobian) << dir << ": receivers without dudx dvdx dudy dvdy (regenerate them)";
    ASSERT_EQ(s.ref_soft.texels(), s.receivers.count()) << dir;
    const std::vector<double> soft(s.ref_soft.data.begin(), s.ref_soft.data.end());
    for (const MethodDesc& m : methods()) {
      if (!m.filtered) continue;  // sm: no footprint
      for (const Lookup kind : {Lookup::Mips, Lookup::Sat}) {
        std::vector<std::unique_ptr<FrameFilter>> filters;
        std::vector<double> rmse;
        std::vector<std::vector<double>> ms(std::size(caps));
        bool refused = false;
        for (const int cap : caps) {
          FilterOptions o;
          o.method = m.name;
          o.blur.radius = radius;
          o.lookup.kind = kind;
          o.lookup.max_anisotropy = cap;
          try {
            filters.push_back(std::make_unique<FrameFilter>(runtime_ptr(), o));
            const FilterResult r = filters.back()->run(s.depth, s.receivers);
            rmse.push_back(eval::error_stats(r.visibility.data, soft, s.traced).rmse);
          } catch (const InputError&) {  // a sat table that cannot hold the method on this map
            refused = true;
            break;
          }
        }
        if (refused) continue;
        for (int run = 0; run < runs; ++run)
          for (size_t c = 0; c < filters.size(); ++c)
            ms[c].push_back(1e3 * filters[c]->run(s.depth, s.receivers).times.reconstruct);
        const double t1 = median(ms[0]), t4 = median(ms[1]), t8 = median(ms[2]);
        std::printf("| %s | %s | %s | %.4f | %.4f | %.4f | %.4f | %+.1f%% / %+.1f%% | %.2f | %.2f / %.2f |\n",
                    s.name.c_str(), m.name.c_str(), kind == Lookup::Mips ? "mips" : "sat", rmse[0], rmse[1], rmse[2],
                    rmse[3], 100.0 * (rmse[1] / rmse[0] - 1.0), 100.0 * (rmse[2] / rmse[0] - 1.0), t1, t4 / t1,
                    t8 / t1);
      }
    }
  }
}

}  // namespace
}  // namespace sf::test

// EVSM's Chebyshev sides against the double twin where their float32 form can overflow.
#include <gtest/gtest.h>

#include <vector>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// evsm4's negative side behind a 50/50 edge of depths 0 and 1 at c- = 42: scaled by 1/|t| its
// second moment reached e^168 and overflowed, and the receiver read lit; it must read the twin's
// 0.5 (sf_evsm_side scales by the larger of |t| and |m1|).
TEST(EvsmSides, NegativeSideBehindAWideEdge) {
  HostImage m(16, 16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) m.at(x, y) = x < 8 ? 0.0f : 1.0f;
  Receivers rx;
  rx.height = 1;
  rx.has_footprint = true;
  for (float d : {0.5f, 0.99f, 0.999f})
    for (float u : {0.45f, 0.5f, 0.55f}) {
      rx.u.push_back(u);
      rx.v.push_back(0.5f);
      rx.d.push_back(d);
      rx.f.push_back(1.0f);
      ++rx.width;
    }
  for (int radius : {0, 2}) {
    FilterOptions o;
    o.method = "evsm4";
    o.evsm.pos = o.evsm.neg = 42.0f;
    o.blur.radius = radius;
    const std::vector<float> got = filter(runtime_ptr(), o, m, rx).visibility.data;
    const std::vector<double> want = ref::filter(o, m, rx);
    for (size_t i = 0; i < got.size(); ++i)
      EXPECT_NEAR(got[i], want[i], 1e-3) << "R " << radius << " u " << rx.u[i] << " d " << rx.d[i];
  }
}

}  // namespace
}  // namespace sf::test

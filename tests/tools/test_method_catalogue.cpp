// Evaluate's catalogue (host/eval/method_catalogue.hpp): every method the library registers has
// an entry, with its colour, grid variants and cost.
#include <gtest/gtest.h>

#include <array>
#include <set>

#include "evaluate.hpp"
#include "method_catalogue.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::test {
namespace {

TEST(MethodCatalogue, EveryLibraryMethodHasAnEntry) {
  std::set<std::array<float, 3>> colours;
  size_t listed = 0;
  for (const MethodDesc& m : methods()) {
    if (!m.header_source.empty()) continue;  // registered from outside the library (a test's)
    EXPECT_TRUE(eval::catalogued(m)) << m.name;
    colours.insert(eval::catalogue_entry(m).colour);
    ++listed;
  }
  EXPECT_EQ(listed, 9u);
  EXPECT_EQ(colours.size(), listed) << "every plot tells the methods apart";
}

TEST(MethodCatalogue, GridsVaryTheParametersTheLabelsName) {
  FilterOptions base;
  base.method = "csm";
  const auto wide = eval::grid_variants(base, eval::Grid::Wide);
  ASSERT_EQ(wide.size(), 6u);
  EXPECT_EQ(eval::catalogue_label(wide.front()), " M=1");
  EXPECT_EQ(eval::catalogue_label(wide.back()), " M=32");
  base.method = "esm";
  EXPECT_EQ(eval::auto_variants(base).size(), 12u);  // 4 exponents x 3 classifications
  EXPECT_EQ(eval::grid_variants(base, eval::Grid::Quick).size(), 2u);
  base.method = "evsm4";
  EXPECT_EQ(eval::catalogue_label(base), " c+=10");
  EXPECT_EQ(eval::grid_variants(base, eval::Grid::Default).size(), 1u);
}

}  // namespace
}  // namespace sf::test

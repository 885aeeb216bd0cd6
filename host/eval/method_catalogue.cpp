// Evaluate's catalogue of the registered methods (method_catalogue.hpp): grids, labels, cost
// coefficients (measured on PoCL, docs/results.md "cost model") and plot colours.
#include "method_catalogue.hpp"

#include <map>
#include <sstream>

#include "evaluate.hpp"

namespace sf::eval {
namespace {

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// One variant of `base` per value, each set by `set`.
template <typename T, typename Set>
std::vector<FilterOptions> variants_of(const FilterOptions& base, const std::vector<T>& values, Set set) {
  std::vector<FilterOptions> out;
  for (const T& v : values) {
    FilterOptions o = base;
    set(o, v);
    out.push_back(o);
  }
  return out;
}

// A parameter in effect as the method resolves it (MethodDesc::parameter_values).
double resolved(const FilterOptions& o, const std::string& key) {
  for (const MethodParameter& p : o.method->parameter_values(o))
    if (p.key == key) return p.value;
  return 0;
}

std::string lbr_label(const FilterOptions& o) { return o.vsm.lbr > 0 ? " lbr=" + num(o.vsm.lbr) : ""; }

CatalogueEntry raw_depth(bool filtered) {
  CatalogueEntry e;
  // sm: one fetch and test per bilinear tap; pcf: every texel of the (2R + 2)^2 support.
  e.cost = filtered ? CostModel{0.0, 8.0, 0.0, 1.2} : CostModel{0.0, 9.0, 0.0, 0.0};
  e.colour = filtered ? std::array<float, 3>{0.55f, 0.55f, 0.55f} : std::array<float, 3>{0.0f, 0.0f, 0.0f};
  return e;
}

CatalogueEntry esm() {
  CatalogueEntry e;
  e.label = [](const FilterOptions& o) { return " c=" + num(o.esm.c); };
  e.variants = [](const FilterOptions& base, Grid g) {
    const std::vector<float> cs = g == Grid::Quick  ? std::vector<float>{40, 80}
                                  : g == Grid::Wide ? std::vector<float>{20, 40, 80, 120, 160}
                                                    : std::vector<float>{40, 80, 160};
    return variants_of(base, cs, [](FilterOptions& o, float c) { o.esm.c = c; });
  };
  e.auto_variants = [](const FilterOptions& base) {
    std::vector<FilterOptions> out;
    for (float c : {20.0f, 40.0f, 80.0f, 160.0f})
      for (EsmClassify k : {EsmClassify::None, EsmClassify::Threshold, EsmClassify::ZMax}) {
        FilterOptions o = base;
        o.esm.c = c;
        o.esm_classify.mode = k;
        out.push_back(o);
      }
    return out;
  };
  e.quick_footprints = true;
  e.cost.reconstruct = 25.0;  // the exponential in log space
  e.colour = {0.85f, 0.1f, 0.1f};
  return e;
}

CatalogueEntry vsm() {
  CatalogueEntry e;
  e.label = lbr_label;
  e.variants = [](const FilterOptions& base, Grid g) {
    const std::vector<float> a =
        g == Grid::Quick ? std::vector<float>{0.0f, 0.2f} : std::vector<float>{0.0f, 0.2f, 0.4f};
    return variants_of(base, a, [](FilterOptions& o, float v) { o.vsm.lbr = v; });
  };
  e.colour = {0.1f, 0.35f, 0.9f};
  return e;
}

CatalogueEntry evsm(bool four) {
  CatalogueEntry e;
  e.label = [](const FilterOptions& o) { return lbr_label(o) + " c+=" + num(resolved(o, "c+")); };
  e.variants = [](const FilterOptions& base, Grid g) {
    if (g != Grid::Wide) return std::vector<FilterOptions>{base};
    return variants_of(base, std::vector<float>{20.0f, 40.0f}, [](FilterOptions& o, float c) { o.evsm.pos = c; });
  };
  e.cost.reconstruct = four ? 40.0 : 9.0;  // two Chebyshev bounds / one
  e.colour = four ? std::array<float, 3>{0.1f, 0.6f, 0.1f} : std::array<float, 3>{0.0f, 0.65f, 0.65f};
  return e;
}

CatalogueEntry msm(bool hausdorff) {
  CatalogueEntry e;
  e.cost.reconstruct = hausdorff ? 50.0 : 60.0;  // Cholesky + cubic (+ the Hausdorff bound)
  e.colour = hausdorff ? std::array<float, 3>{0.6f, 0.3f, 0.0f} : std::array<float, 3>{0.9f, 0.5f, 0.0f};
  return e;
}

CatalogueEntry csm() {
  CatalogueEntry e;
  e.label = [](const FilterOptions& o) { return " M=" + std::to_string(o.csm.order); };
  e.variants = [](const FilterOptions& base, Grid g) {
    const std::vector<int> orders = g == Grid::Quick  ? std::vector<int>{4, 8}
                                    : g == Grid::Wide ? std::vector<int>{1, 2, 4, 8, 16, 32}
                                                      : std::vector<int>{2, 4, 8, 16};
    return variants_of(base, orders, [](FilterOptions& o, int M) { o.csm.order = M; });
  };
  e.quick_footprints = true;
  // One sin/cos pair per channel pair at the transform; a term per channel at the lookup.
  e.cost = CostModel{1.0, 0.0, 6.0, 0.0};
  e.colour = {0.6f, 0.1f, 0.75f};
  return e;
}

const std::map<std::string, CatalogueEntry>& catalogue() {
  static const std::map<std::string, CatalogueEntry> table = {
      {"sm", raw_depth(false)}, {"pcf", raw_depth(true)},     {"esm", esm()},
      {"vsm", vsm()},           {"evsm2", evsm(false)},       {"evsm4", evsm(true)},
      {"msm", msm(false)},      {"msm-hausdorff", msm(true)}, {"csm", csm()},
  };
  return table;
}

}  // namespace

const CatalogueEntry& catalogue_entry(const Method& m) {
  static const CatalogueEntry fallback;
  const auto it = catalogue().find(m.name());
  return it == catalogue().end() ? fallback : it->second;
}

bool catalogued(const Method& m) { return catalogue().count(m.name()) > 0; }

std::string catalogue_label(const FilterOptions& o) {
  const CatalogueEntry& e = catalogue_entry(o.method);
  return e.label ? e.label(o) : std::string();
}

std::vector<FilterOptions> grid_variants(const FilterOptions& base, Grid grid) {
  const CatalogueEntry& e = catalogue_entry(base.method);
  return e.variants ? e.variants(base, grid) : std::vector<FilterOptions>{base};
}

std::vector<FilterOptions> auto_variants(const FilterOptions& base) {
  const CatalogueEntry& e = catalogue_entry(base.method);
  return e.auto_variants ? e.auto_variants(base) : grid_variants(base, Grid::Wide);
}

}  // namespace sf::eval

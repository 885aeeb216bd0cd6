// The parameter grid: every method's variants (evaluate's catalogue, method_catalogue.hpp) crossed
// with radii, lookups and storages, and the labels of its rows.
#include <algorithm>
#include <sstream>

#include "evaluate.hpp"
#include "method_catalogue.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {

Grid parse_grid(const std::string& name) {
  if (name == "quick") return Grid::Quick;
  if (name == "default") return Grid::Default;
  if (name == "wide") return Grid::Wide;
  throw InputError("--grid must be quick, default or wide, got '" + name + "'");
}

std::vector<std::string> parse_methods(const std::string& list) {
  std::vector<std::string> out;
  if (list == "all") {
    for (const auto& m : methods()) out.push_back(m.name);
    return out;
  }
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    method(item);  // throws naming the known methods
    if (std::find(out.begin(), out.end(), item) == out.end()) out.push_back(item);
  }
  if (out.empty()) throw InputError("the method list '" + list + "' names no method ('all' or a comma-separated list)");
  if (out.empty()) throw InputError("--methods lists no method");
  return out;
}

std::string config_label(const FilterOptions& o) {
  std::ostringstream s;
  const MethodDesc& m = *o.method;
  s << o.method << catalogue_label(o);
  if (m.filtered) s << " R=" << o.blur.radius;
  if (!m.raw_depth) {
    if (o.lookup.kind == Lookup::Mips) s << " mips";
    if (o.lookup.kind == Lookup::Sat) s << " sat";
    s << " " << storage_name(o.storage);
  }
  if (classify_mode(o) == EsmClassify::ZMax) s << " zmax";
  if (classify_mode(o) == EsmClassify::Threshold) s << " threshold";
  return s.str();
}

std::vector<FilterOptions> make_grid(const std::vector<std::string>& names, Grid grid, double max_footprint,
                                     double sref_bias) {
  const bool quick = grid == Grid::Quick, wide = grid == Grid::Wide;
  const std::vector<int> radii = quick  ? std::vector<int>{1, 3}
                                 : wide ? std::vector<int>{0, 1, 3, 7, 15}
                                        : std::vector<int>{0, 1, 3, 7};
  std::vector<Lookup> lookups{Lookup::Bilinear};
  if (max_footprint > 1.0) {
    lookups.push_back(Lookup::Mips);
    if (!quick) lookups.push_back(Lookup::Sat);
  }
  std::vector<FilterOptions> out;
  for (const auto& name : names) {
    FilterOptions base;
    base.method = method(name);
    const MethodDesc& m = *base.method;
    if (m.raw_depth) base.depth_test.bias = float(sref_bias);
    const std::vector<FilterOptions> variants = grid_variants(base, grid);
    for (const auto& v : variants) {
      if (!m.filtered) {  // the unfiltered test: no radius, no lookup
        out.push_back(v);
        continue;
      }
      for (int r : radii) {
        if (m.raw_depth) {  // follows the radius, reads the depth map: no lookup table, no storage
          FilterOptions o = v;
          o.blur.radius = r;
          out.push_back(o);
          continue;
        }
        for (Lookup lk : lookups) {
          if (quick && lk != Lookup::Bilinear && !catalogue_entry(base.method).quick_footprints) continue;
          FilterOptions o = v;
          o.blur.radius = r;
          o.lookup.kind = lk;
          out.push_back(o);
        }
      }
    }
    // Storage formats other than f32, without and with a prefilter, within each one's limits.
    if (!quick && !m.raw_depth) {
      for (const StorageLimit& l : m.storages) {
        if (l.storage == Storage::F32) continue;
        FilterOptions o = variants.front();
        o.storage = l.storage;
        o = m.fitted(o);
        o.blur.radius = 0;
        out.push_back(o);
        o.blur.radius = 3;
        out.push_back(o);
      }
    }
  }
  return out;
}

}  // namespace sf::eval

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

MethodLists parse_evaluated_methods(const std::string& list) {
  MethodLists out;
  std::stringstream ss(list);
  std::string item, hard;
  auto add_soft = [&](SoftMethod m) {
    if (std::find(out.soft.begin(), out.soft.end(), m) == out.soft.end()) out.soft.push_back(m);
  };
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    if (item == "soft") {
      for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}) add_soft(m);
    } else if (item == "all" ||
               std::any_of(methods().begin(), methods().end(), [&](const MethodDesc& m) { return m.name == item; })) {
      hard += (hard.empty() ? "" : ",") + item;
    } else {
      try {
        add_soft(find_soft_method(item));
      } catch (const InputError&) {
        std::string known;
        for (const auto& m : methods()) known += m.name + ", ";
        throw InputError("unknown method '" + item + "' (known: " + known +
                         "the soft methods pcss, cssm, ssmm, ssmm-improved; all: every non-soft one; soft: the four)");
      }
    }
  }
  if (!hard.empty()) out.hard = parse_methods(hard);
  if (out.hard.empty() && out.soft.empty())
    throw InputError("the method list '" + list + "' names no method ('all', 'soft' or a comma-separated list)");
  return out;
}

std::vector<SoftOptions> make_soft_grid(const std::vector<SoftMethod>& methods, Grid grid, const SoftOptions& from) {
  const bool quick = grid == Grid::Quick, wide = grid == Grid::Wide;
  std::vector<SoftOptions> out;
  for (SoftMethod m : methods) {
    SoftOptions base = from;
    base.method = m;
    switch (m) {
      case SoftMethod::Pcss:
        out.push_back(base);
        break;
      case SoftMethod::Cssm:
        for (int order : quick ? std::vector<int>{4} : std::vector<int>{4, 8, 16})
          for (Lookup lk : {Lookup::Mips, Lookup::Sat}) {
            if (lk == Lookup::Sat && order > 4 && !wide) continue;  // the SAT at M > 4: seconds a frame on PoCL
            SoftOptions o = base;
            o.cssm.order = order;
            o.cssm.lookup = lk;
            out.push_back(o);
          }
        break;
      case SoftMethod::Ssmm:
      case SoftMethod::SsmmImproved:
        for (int n : quick                           ? std::vector<int>{4}
                     : m == SoftMethod::Ssmm || wide ? std::vector<int>{3, 4, 6}
                                                     : std::vector<int>{3, 4}) {
          SoftOptions o = base;
          o.ssmm.n = n;
          out.push_back(o);
        }
        break;
    }
  }
  return out;
}

std::string soft_label(const SoftOptions& o) {
  std::ostringstream s;
  s << soft_method_name(o.method);
  if (o.method == SoftMethod::Cssm)
    s << " M=" << o.cssm.order << (o.cssm.lookup == Lookup::Sat ? " sat" : " mips")
      << (o.cssm.storage != Storage::F32 ? std::string(" ") + storage_name(o.cssm.storage) : std::string());
  if (o.method == SoftMethod::Ssmm || o.method == SoftMethod::SsmmImproved) s << " n=" << o.ssmm.n;
  return s.str();
}

std::string config_label(const FilterOptions& o) {
  std::ostringstream s;
  const MethodDesc& m = *o.method;
  s << o.method << catalogue_label(o);
  if (m.filtered) s << " R=" << o.blur.radius;
  if (!m.raw_depth) {
    if (o.lookup.kind == Lookup::Mips) s << " mips";
    if (o.lookup.kind == Lookup::Sat) s << " sat";
    const int aniso = o.lookup.max_anisotropy;
    if (o.lookup.kind != Lookup::Bilinear && aniso != LookupOptions{}.max_anisotropy)
      s << (aniso == 1 ? std::string(" iso") : " aniso" + std::to_string(aniso));
    s << " " << storage_name(o.storage);
  }
  if (classify_mode(o) == EsmClassify::ZMax) s << " zmax";
  if (classify_mode(o) == EsmClassify::Threshold) s << " threshold";
  return s.str();
}

std::vector<FilterOptions> make_grid(const std::vector<std::string>& names, Grid grid, double max_footprint,
                                     double sref_bias, bool jacobian) {
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
          if (jacobian && !quick && lk != Lookup::Bilinear) {  // the isotropic twin (footprint.hpp)
            o.lookup.max_anisotropy = 1;
            out.push_back(o);
          }
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

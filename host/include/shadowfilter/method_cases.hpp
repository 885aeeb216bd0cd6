#pragma once
// The method x storage cases the method tests and sf_bench both walk: one basis method, one
// storage format it accepts and a csm order, with the options that run them.
#include <string>
#include <vector>

#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"

namespace sf {

struct MethodCase {
  std::string method;
  Storage storage = Storage::F32;
  int csm_order = 8;
  FilterOptions options() const {
    FilterOptions o;
    o.method = method;
    o.storage = storage;
    o.csm.order = csm_order;
    return find_method(method).fitted(o);  // within the storage's limits (esm f16: c = 20)
  }
  std::string label() const {
    std::string s = method + "_" + storage_name(storage);
    if (find_method(method).order_sets_channels) s += "_M" + std::to_string(csm_order);
    for (char& c : s)
      if (c == '-') c = '_';
    return s;
  }
};

// Every basis method (not sm / pcf) with every storage it accepts, in registry order; csm once
// per order of `csm_orders` (the method whose channel count follows its order).
inline std::vector<MethodCase> method_storage_cases(const std::vector<int>& csm_orders) {
  std::vector<MethodCase> out;
  for (const auto& m : methods()) {
    if (m.raw_depth) continue;
    for (Storage s : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
      if (!m.accepts(s)) continue;
      if (!m.order_sets_channels) {  // a fixed channel count: one case
        out.push_back({m.name, s, 8});
        continue;
      }
      for (int order : csm_orders) out.push_back({m.name, s, order});
    }
  }
  return out;
}

}  // namespace sf

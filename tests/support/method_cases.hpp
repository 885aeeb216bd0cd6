#pragma once
// The method x storage cases the method tests and sf_bench both walk: one basis method, one
// storage format it accepts and a csm order, with the options that run them.
#include <string>
#include <vector>

#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"

namespace sf {

struct MethodCase {
  Method method;
  Storage storage = Storage::F32;
  int csm_order = 8;
  FilterOptions options() const {
    FilterOptions o;
    o.method = method;
    o.storage = storage;
    o.csm.order = csm_order;
    return method->fitted(o);  // within the storage's limits (esm f16: c = 20)
  }
  std::string label() const {
    std::string s = method.name() + "_" + storage_name(storage);
    if (method->order_sets_channels) s += "_M" + std::to_string(csm_order);
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
        out.push_back({m, s, 8});
        continue;
      }
      for (int order : csm_orders) out.push_back({m, s, order});
    }
  }
  return out;
}

}  // namespace sf

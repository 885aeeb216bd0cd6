#pragma once
// Small helpers evaluate's parts share: medians of timings, numbers and lookups as labels print
// them.
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "shadowfilter/options.hpp"

namespace sf::eval::detail {

template <typename T>
double median(std::vector<T> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? double(v[n / 2]) : 0.5 * (double(v[n / 2 - 1]) + double(v[n / 2]));
}

inline const char* lookup_name(Lookup k) { return k == Lookup::Mips ? "mips" : k == Lookup::Sat ? "sat" : "bilinear"; }

inline std::string fmt(double v, int prec = 4) {
  std::ostringstream s;
  s.precision(prec);
  s << v;
  return s.str();
}

}  // namespace sf::eval::detail

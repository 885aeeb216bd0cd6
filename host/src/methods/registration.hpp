#pragma once
// What the per-method registrations (host/src/methods/*.cpp) share: the small helpers they
// validate and pack with. Each file's builder is declared where it is listed (registry.cpp).
#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "shadowfilter/errors.hpp"
#include "shared_types.clh"
#include "shadowfilter/methods.hpp"

namespace sf::registration {

template <typename T>
std::vector<uint8_t> bytes_of(const T& v) {
  std::vector<uint8_t> b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

// Shortest text of a number, as declarations and messages show it.
inline std::string num(double v) { return parameter_text(v); }

inline void require_finite(float v, const char* field) {
  if (!std::isfinite(v)) throw InputError(std::string(field) + " must be a finite number");
}

// ln of the least and largest magnitude of one basis channel over a map.
struct LogRange {
  double lo, hi;
};

// The refusal of a basis of exponentials on `map` when the summed-area table cannot hold one of
// its channels within `relative_error` (sat_precision.hpp); "" when it can. `log_ranges(c)` gives
// the channels' LogRanges over map.range for the exponent c, which `exponent` names
// ("FilterOptions::esm.c"), and `keeps` says what the tolerance keeps ("a visibility error of
// 0.001"). The message names the limit passed and the largest exponent within all of them (every
// limit holds for a smaller c once it holds for c: the magnitudes' logarithms scale with c).
std::string sat_exponential_refusal(const std::string& method, const char* exponent, double c,
                                    const std::function<std::vector<LogRange>(double c)>& log_ranges, const SatMap& map,
                                    double relative_error, const std::string& keeps);

// The storage must be one the method lists (MethodDesc::storages); `why` says why the others
// do not work.
void check_storage(const MethodDesc& m, const FilterOptions& o, const std::string& why);

// The same storages, each with no limit of its own.
std::vector<StorageLimit> plain_storages(std::initializer_list<Storage> list);

}  // namespace sf::registration

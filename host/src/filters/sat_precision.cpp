#include "shadowfilter/sat_precision.hpp"

#include <cfloat>
#include <cmath>

namespace sf {

double sat_entry_error(bool fp64) { return std::ldexp(1.0, fp64 ? -46 : -42); }

namespace {
double texels_of(const SatMap& map) { return double(map.texels() > 0 ? map.texels() : 1); }
}  // namespace

double sat_max_log_value(const SatMap& map) { return std::log(double(FLT_MAX) / 2) - std::log(texels_of(map)); }

double sat_max_log_ratio(const SatMap& map, double relative_error) {
  return std::log(relative_error / (8.0 * sat_entry_error(map.fp64) * texels_of(map)));
}

double sat_min_log_value(double relative_error) { return std::log(8.0 * double(FLT_MIN) / relative_error); }

}  // namespace sf

#pragma once
// How precise a box mean from the summed-area table is (kernels/sat.cl, docs/numerics.md "Lookup
// limits"), and the facts about a map that precision depends on. A box sum is the difference of
// table entries of the whole map's magnitude, stored as float32 pairs (hi + lo), so the table
// keeps a precision relative to its largest entries, not to the box: a basis whose values span
// a large ratio over the map (ESM, EVSM: exponentials of the depth) loses the darkest boxes, its
// sums can pass the float32 range, and its smallest values can fall below it.
#include <cstddef>

#include "shadowfilter/map_range.hpp"

namespace sf {

// The map a summed-area table is built of, as far as its precision goes.
struct SatMap {
  MapRange range;  // least and largest finite depth
  int width = 0, height = 0;
  bool fp64 = true;  // the device accumulates in double (cl_khr_fp64); else float-float
  size_t texels() const { return size_t(width) * size_t(height); }
};

// Relative error of one table entry (hi + lo) against the exact sum of the values above-left of
// it: 2^-46 with the double accumulator, 2^-42 with float-float. These are 4x and 3x the worst
// entries measured on a 4096 x 4096 table (3.6e-15 and 7.4e-14, tests/core/test_sat.cpp SatLarge):
// rounding errors along an entry's path add up like a random walk, so the margin covers maps up
// to the 2^31 values the pipeline accepts.
double sat_entry_error(bool fp64);

// Where the table holds a channel whose magnitudes lie in [exp(log_lo), exp(log_hi)] over the
// map (all of one sign) with box means within `relative_error` of their value. Three limits:
//  - sums: the whole channel's sum, its largest entry, must stay a float32 (with a factor 2 of
//    margin): log_hi <= sat_max_log_value(map), i.e. ln(FLT_MAX / 2) - ln N;
//  - span: four entries, each within eps of a sum of at most N values of magnitude at most
//    exp(log_hi), against a box mean of at least exp(log_lo) over at least one texel: relative
//    error <= 4 eps N exp(log_hi - log_lo), half the budget: log_hi - log_lo <=
//    sat_max_log_ratio(map, relative_error) = ln(relative_error / (8 eps N));
//  - small values: an entry's lo part below FLT_MIN may be flushed to zero (an absolute error of
//    up to FLT_MIN per entry), against a box mean of at least exp(log_lo), the other half:
//    log_lo >= sat_min_log_value(relative_error) = ln(8 FLT_MIN / relative_error).
double sat_max_log_value(const SatMap& map);
double sat_max_log_ratio(const SatMap& map, double relative_error);
double sat_min_log_value(double relative_error);

}  // namespace sf

// ESM (kernels/methods/esm.clh): B = exp(c (z - 1/2)), v = exp(-c (d - 1/2)) bar(B).
#include <algorithm>
#include <cmath>
#include <limits>

#include "registration.hpp"

namespace sf::registration {
namespace {

// Largest exponent whose centred storage exp(c (z - 1/2)) stays within normal float32 numbers:
// exp(+-c/2) within [FLT_MIN, FLT_MAX] means c/2 <= 87.3.
constexpr float kMaxCFloat32 = 174.0f;
// float16: exp(c/2) <= 65504 (the largest half) means c <= 2 ln 65504 = 22.18.
constexpr float kMaxCFloat16 = 22.0f;
// Where a grid or table puts esm in f16: the largest round exponent under the limit.
constexpr float kFloat16GridC = 20.0f;
// The summed-area table's share of the visibility error (docs/numerics.md, "Lookup limits").
constexpr double kSatVisibilityError = 1e-3;

}  // namespace

MethodDesc esm_method() {
  MethodDesc m;
  m.name = "esm";
  m.summary = "exponential shadow maps: B = exp(c z), v = exp(-c d) bar(B)";
  m.header = "methods/esm.clh";
  m.classifiable = true;
  m.channel_count = [](const FilterOptions&) { return 1; };
  m.parameters = {Parameter::real("FilterOptions::esm.c", "--esm-c", "C",
                                  "ESM exponent c of exp(c z): sharper and less leaking when larger, up to the "
                                  "storage's limit")
                      .with_default(EsmOptions{}.c)
                      .within({0, std::numeric_limits<double>::infinity(), true})
                      .on(&FilterOptions::esm, &EsmOptions::c)};
  m.reads = {"FilterOptions::esm_classify.mode"};
  m.storages = {{Storage::F32, "c <= 174", {}},
                {Storage::F16, "c <= 22", [](FilterOptions& o) { o.esm.c = std::min(o.esm.c, kFloat16GridC); }}};
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o, "exp(c z) is unbounded, so unorm cannot hold it");
    const bool half = o.storage == Storage::F16;
    const float limit = half ? kMaxCFloat16 : kMaxCFloat32;
    if (o.esm.c > limit) {
      std::ostringstream s;
      s << "FilterOptions::esm.c " << o.esm.c << " exceeds the " << (half ? "float16" : "float32") << " limit of "
        << limit
        << (half ? " (exp(c/2) must stay below 65504, the largest half)" : " (exp(c/2) must stay a normal float)");
      throw InputError(s.str());
    }
  };
  // v = bar(B') exp(c (1/2 - d)) moves by the relative error of the box mean bar(B') times v (and
  // no more once clamped at 1): box means within kSatVisibilityError keep the table's share of
  // the error there. B' = exp(c (z - 1/2)) lies in [exp(c (zmin - 1/2)), exp(c (zmax - 1/2))].
  m.sat_limit = [](const FilterOptions& o, const SatMap& map) {
    const MapRange r = map.range;
    auto ranges = [r](double c) { return std::vector<LogRange>{{c * (r.min - 0.5), c * (r.max - 0.5)}}; };
    return sat_exponential_refusal("esm", "FilterOptions::esm.c", o.esm.c, ranges, map, kSatVisibilityError,
                                   "a visibility error of 0.001");
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(sf_esm_params{o.esm.c}); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.scalar = [](const FilterOptions& o) {
    const double c = o.esm.c;
    ScalarMethod s;
    s.channels = 1;
    s.basis = [c](double z, double* b) { b[0] = std::exp(c * (z - 0.5)); };
    s.visibility = [c](const double* b, double d) { return std::clamp(std::exp(-c * (d - 0.5)) * b[0], 0.0, 1.0); };
    return s;
  };
  m.parameter_values = [](const FilterOptions& o) { return std::vector<MethodParameter>{{"c", o.esm.c}}; };
  return m;
}

}  // namespace sf::registration

// Every floating-point field of FilterOptions is finite: a NaN or an infinity is an input error
// whether or not the method reads the field, so that no option is silently a default or passed
// on as NaN. The methods' own validation then checks the ranges of the fields they read.
#include <cmath>
#include <string>
#include <utility>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/options.hpp"

namespace sf {

void require_finite_options(const FilterOptions& o) {
  const std::pair<const char*, float> fields[] = {
      {"FilterOptions::esm.c", o.esm.c},
      {"FilterOptions::depth_test.bias", o.depth_test.bias.value_or(0.0f)},
      {"FilterOptions::receiver_plane.max_slope", o.receiver_plane.max_slope},
      {"FilterOptions::receiver_plane.slope_bias", o.receiver_plane.slope_bias},
      {"FilterOptions::vsm.min_variance", o.vsm.min_variance},
      {"FilterOptions::vsm.lbr", o.vsm.lbr},
      {"FilterOptions::evsm.pos", o.evsm.pos},
      {"FilterOptions::evsm.neg", o.evsm.neg},
      {"FilterOptions::msm.moment_bias", o.msm.moment_bias},
      {"FilterOptions::csm.alpha", o.csm.alpha},
      {"FilterOptions::csm.offset", o.csm.offset},
      {"FilterOptions::csm.scale", o.csm.scale},
      {"FilterOptions::blur.sigma", o.blur.sigma},
      {"FilterOptions::esm_classify.zmax_offset", o.esm_classify.zmax_offset},
      {"FilterOptions::esm_classify.threshold_eps", o.esm_classify.threshold_eps},
  };
  for (const auto& [name, value] : fields)
    if (!std::isfinite(value)) throw InputError(std::string(name) + " must be a finite number");
  if (o.depth_range && (std::isnan(o.depth_range->min) || std::isnan(o.depth_range->max)))
    throw InputError("FilterOptions::depth_range must not be NaN (min > max: a map without finite depths)");
}

}  // namespace sf

// Every floating-point field of FilterOptions is finite: a NaN or an infinity is an input error
// whether or not the method reads the field, so that no option is silently a default or passed
// on as NaN. The fields are the declared ones (parameters.hpp): the FilterOptions-wide knobs and
// every registered method's parameters. The methods' own validation then checks the ranges of
// the fields they read.
#include <cmath>
#include <string>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"

namespace sf {

void require_finite_options(const FilterOptions& o) {
  const std::vector<const Parameter*> declared = declared_parameters();
  for (const Parameter* p : declared)
    if (p->type == ParameterType::Real && !std::isfinite(p->get(o)))
      throw InputError(p->field + " must be a finite number");
  // A stored parameter no registered method declares is a misspelt key, not a default.
  for (const auto& [key, value] : o.parameters) {
    const std::string field = "FilterOptions::parameters." + key;
    bool known = false;
    for (const Parameter* p : declared) known = known || p->field == field;
    if (!known) throw InputError(field + " is no registered method's parameter");
    if (!std::isfinite(value)) throw InputError(field + " must be a finite number");
  }
  if (o.depth_range && (std::isnan(o.depth_range->min) || std::isnan(o.depth_range->max)))
    throw InputError("FilterOptions::depth_range must not be NaN (min > max: a map without finite depths)");
}

}  // namespace sf

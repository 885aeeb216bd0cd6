#include <cmath>
#include <iomanip>
#include <stdexcept>
#include <string>
#include <map>
#include <sstream>

#include "filter_options.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/classify.hpp"

namespace sf::cli {

std::string prefilter_summary(const FilterOptions& o) {
  std::ostringstream s;
  if (o.blur.radius > 0) {
    const float sigma = o.blur.sigma > 0 ? o.blur.sigma : default_blur_sigma(o.blur.radius);
    s << "gaussian R=" << o.blur.radius << " sigma=" << sigma;
  } else {
    s << "no prefilter";
  }
  switch (o.lookup.kind) {
    case Lookup::Mips:
      s << ", trilinear (mips) lookup";
      break;
    case Lookup::Sat:
      s << ", box (sat) lookup";
      break;
    default:
      s << ", bilinear lookup";
      break;
  }
  if (classify_mode(o) == EsmClassify::ZMax)
    s << ", zmax classification offset=" << o.esm_classify.zmax_offset;
  else if (classify_mode(o) == EsmClassify::Threshold)
    s << ", threshold classification eps=" << std::setprecision(4) << esm_threshold_eps(o);
  return s.str();
}

}  // namespace sf::cli

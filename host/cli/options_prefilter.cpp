#include <sstream>

#include "filter_options.hpp"
#include "shadowfilter/kernels.hpp"

namespace sf::cli {

void add_prefilter_options(CLI::App& c, FilterOptions& o) {
  c.add_option("--blur-radius", o.blur.radius, "Gaussian prefilter radius R (taps -R..R)")
      ->capture_default_str();
  c.add_option("--blur-sigma", o.blur.sigma, "Gaussian sigma in texels (0 = (2R+1)/6)")
      ->capture_default_str();
}

std::string prefilter_summary(const FilterOptions& o) {
  std::ostringstream s;
  if (o.blur.radius > 0) {
    const float sigma = o.blur.sigma > 0 ? o.blur.sigma : default_blur_sigma(o.blur.radius);
    s << "gaussian R=" << o.blur.radius << " sigma=" << sigma;
  } else {
    s << "no prefilter";
  }
  s << ", bilinear lookup";
  return s.str();
}

}  // namespace sf::cli

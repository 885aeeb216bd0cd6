#include <cmath>
#include <iomanip>
#include <stdexcept>
#include <string>
#include <map>
#include <sstream>

#include "filter_options.hpp"
#include "help_format.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/kernels.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf::cli {

void add_prefilter_options(CLI::App& c, FilterOptions& o) {
  c.add_option("--blur-radius", o.blur.radius, "Gaussian prefilter radius R (taps -R..R)")->capture_default_str();
  // Given, sigma must be a positive finite number; not given, it is (2R+1)/6 (FilterOptions's 0).
  c.add_option("--blur-sigma", o.blur.sigma, "Gaussian sigma in texels (default (2R+1)/6)")
      ->check(CLI::Validator(
          [](const std::string& text) {
            float v = 0.0f;
            try {
              size_t used = 0;
              v = std::stof(text, &used);
              if (used != text.size()) return std::string("must be a number, got '" + text + "'");
            } catch (const std::exception&) {
              return std::string("must be a number, got '" + text + "'");
            }
            return std::isfinite(v) && v > 0.0f ? std::string() : "must be a positive finite number, got " + text;
          },
          "POSITIVE"));
  const std::map<std::string, Lookup> lookups{
      {"bilinear", Lookup::Bilinear}, {"mips", Lookup::Mips}, {"sat", Lookup::Sat}};
  c.add_option("--lookup", o.lookup.kind,
               "Lookup at the receivers: bilinear | mips (trilinear at LOD log2 f) | sat (box of "
               "side f); f = the receivers' footprint channel, 1 when missing")
      ->transform(named_values(lookups))
      ->type_name(value_names(lookups))
      ->default_str("bilinear");
  const std::map<std::string, EsmClassify> modes{{"auto", EsmClassify::Auto},
                                                 {"none", EsmClassify::None},
                                                 {"zmax", EsmClassify::ZMax},
                                                 {"threshold", EsmClassify::Threshold}};
  c.add_option("--esm-classify", o.esm_classify.mode,
               "ESM failure classification: auto (zmax for esm, none otherwise) | none | zmax | threshold; "
               "flagged receivers fall back to a 2x2 PCF of the ESM test")
      ->transform(named_values(modes))
      ->type_name(value_names(modes))
      ->default_str("auto");
  c.add_option("--esm-zmax-offset", o.esm_classify.zmax_offset,
               "zmax: flag when a texel in the lookup's support has z > d + offset")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 1.0f));
  c.add_option("--esm-threshold-eps", o.esm_classify.threshold_eps,
               "threshold: flag when exp(-c d) bar(B) > 1 + eps (negative: exp(c offset)(1+1e-5) - 1, "
               "a subset of zmax)")
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

#include <sstream>

#include "filter_options.hpp"

namespace sf::cli {

void add_method_options(CLI::App& c, FilterOptions& o) {
  c.add_option("--method", o.method, "Filtering method (see `shadowfilter methods`)")->capture_default_str();
  c.add_option("--esm-c", o.esm.c, "ESM exponent c")->capture_default_str();
}

std::string method_summary(const FilterOptions& o) {
  std::ostringstream s;
  s << o.method;
  if (o.method == "esm") s << " c=" << o.esm.c;
  return s.str();
}

}  // namespace sf::cli

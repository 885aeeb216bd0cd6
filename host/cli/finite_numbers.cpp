#include "finite_numbers.hpp"

#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <string>

namespace sf::cli {
namespace {

// Parses like CLI11 (strtold) and rejects what would not be a finite float. Text that is not a
// number at all passes through: the option's own conversion then reports it.
std::string finite_number(const std::string& text) {
  if (text.empty()) return {};
  char* end = nullptr;
  const long double v = std::strtold(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return {};
  // Floats are the narrowest number options: |v| beyond FLT_MAX would be stored as infinity.
  if (std::isfinite(v) && std::fabs(v) <= FLT_MAX) return {};
  return "must be a finite number, got '" + text + "'";
}

}  // namespace

void require_finite_numbers(CLI::App& app) {
  // No description: the help keeps showing FLOAT.
  const CLI::Validator finite(finite_number, "");
  // The type name carries the option's other validators after a colon ("FLOAT:FLOAT in [0 - 1]").
  for (CLI::Option* o : app.get_options())
    if (o->get_type_name().rfind("FLOAT", 0) == 0) o->check(finite);
  for (CLI::App* sub : app.get_subcommands({})) require_finite_numbers(*sub);
}

}  // namespace sf::cli

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

CLI::Option* add_light_size_option(CLI::App* command, std::vector<double>& sides, const std::string& help) {
  auto parse = [&sides](const std::string& text) {
    std::vector<double> v;
    size_t start = 0;
    for (;;) {
      const size_t comma = text.find(',', start);
      const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      char* end = nullptr;
      const double x = item.empty() ? NAN : std::strtod(item.c_str(), &end);
      v.push_back(!item.empty() && *end == '\0' && x >= 0.0 && x <= FLT_MAX ? x : NAN);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (v.size() > 2 || !std::isfinite(v[0]) || !std::isfinite(v.back()))
      throw CLI::ValidationError("--light-size", "must be a finite number >= 0 (L) or two (W,H), got '" + text + "'");
    sides = v;
  };
  return command->add_option_function<std::string>("--light-size", parse, help)->type_name("L|W,H");
}

void require_finite_numbers(CLI::App& app) {
  // No description: the help keeps showing FLOAT.
  const CLI::Validator finite(finite_number, "");
  // The type name carries the option's other validators after a colon ("FLOAT:FLOAT in [0 - 1]").
  for (CLI::Option* o : app.get_options())
    if (o->get_type_name().rfind("FLOAT", 0) == 0) o->check(finite);
  for (CLI::App* sub : app.get_subcommands({})) require_finite_numbers(*sub);
}

}  // namespace sf::cli

#include "light_list.hpp"

#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "input_file.hpp"
#include "list_lines.hpp"
#include "output_file.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

const char* const kKeys = "weight=W, size=L or size=W,H";

// The whole of `text` as a number >= 0 that a float holds (what the device computes with), or NaN.
double list_value(const std::string& text) {
  if (text.empty()) return NAN;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (*end != '\0' || errno == ERANGE || !std::isfinite(value) || value < 0.0 || value > double(FLT_MAX)) return NAN;
  return value;
}

}  // namespace

std::vector<LightListEntry> read_light_list(const std::string& list) {
  io::require_regular_file(list, "light list");
  io::record_input(list);
  std::ifstream in(list, std::ios::binary);
  if (!in) throw InputError("light list '" + list + "': cannot open it");
  return io::with_out_of_memory_named(list, "light list", [&] { return parse_light_list(in, list); });
}

std::vector<LightListEntry> parse_light_list(std::istream& in, const std::string& list) {
  const std::filesystem::path dir = std::filesystem::path(list).parent_path();
  std::vector<LightListEntry> lights;
  ListLines lines(in, list);
  std::string line;
  while (lines.next(line)) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::string map, receivers, item;
    if (!(fields >> map)) continue;
    const std::string where = lines.where();
    if (!(fields >> receivers)) throw InputError(where + ": expected SHADOWMAP RECEIVERS [" + kKeys + "]");
    if (lights.size() == kMaxLights)
      throw InputError(where + ": more than " + std::to_string(kMaxLights) + " lights; a list holds at most " +
                       std::to_string(kMaxLights));
    LightListEntry light;
    light.where = where;
    light.shadow_map = (dir / map).string();
    light.receivers = (dir / receivers).string();
    bool has_weight = false, has_size = false;
    while (fields >> item) {
      const size_t eq = item.find('=');
      const std::string key = item.substr(0, eq);
      bool* seen = key == "weight" ? &has_weight : key == "size" ? &has_size : nullptr;
      if (eq == std::string::npos || !seen) throw InputError(where + ": unknown '" + item + "' (" + kKeys + ")");
      if (*seen) throw InputError(where + ": " + key + " is given twice");
      *seen = true;
      std::string text = item.substr(eq + 1), second;
      if (const size_t comma = text.find(','); key == "size" && comma != std::string::npos) {
        second = text.substr(comma + 1);
        text.resize(comma);
        light.height = list_value(second);
        if (std::isnan(light.height))
          throw InputError(where + ": " + item + " is not two numbers >= 0 that a float holds (" + kKeys + ")");
      }
      const double value = list_value(text);
      if (std::isnan(value))
        throw InputError(where + ": " + item + " is not a number >= 0 that a float holds (" + kKeys + ")");
      (key == "weight" ? light.weight : light.size) = value;
    }
    lights.push_back(std::move(light));
  }
  if (lights.empty()) throw InputError("the light list '" + list + "' holds no light");
  return lights;
}

}  // namespace sf::cli

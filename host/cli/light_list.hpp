#pragma once
// The light list of `soft --lights FILE`: one light a line, `SHADOWMAP RECEIVERS [weight=W]
// [size=L | size=W,H]` (a square light or a rectangle, W along the map's u axis), fields separated by blanks, paths
// relative to the list's directory, text after '#' ignored.
#include <cstddef>
#include <istream>
#include <limits>
#include <string>
#include <vector>

namespace sf::cli {

// The most lights a list may hold (each light's map and receivers stay in memory together).
inline constexpr size_t kMaxLights = 256;

struct LightListEntry {
  std::string where;                                       // "LIST:LINE"
  std::string shadow_map, receivers;                       // relative to the list's directory
  double weight = 1.0;                                     // weight=W: >= 0, finite as a float
  double size = std::numeric_limits<double>::quiet_NaN();  // size=L (>= 0, finite as a float); NaN: the map's header
  double height = -1.0;                                    // size=W,H: H; < 0: a square
};

// InputError naming the line for a line without both files, a key other than weight and size, a
// key given twice, a value that is not a number finite as a float (1e39, nan, "heavy") or is
// negative; lines are at most kMaxListLineBytes (list_lines.hpp), lights at most kMaxLights; a
// list without lights is refused. The list must be a regular file (io::require_regular_file).
std::vector<LightListEntry> read_light_list(const std::string& list);
// The same from text already open; `list` names it in messages and gives the paths' directory.
std::vector<LightListEntry> parse_light_list(std::istream& in, const std::string& list);

}  // namespace sf::cli

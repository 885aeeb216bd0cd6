#pragma once
// Help a newcomer can read without the source: every line wrapped to the terminal's width (80
// when the output is not a terminal), enum options that show and accept their names only.
#include <CLI/CLI.hpp>

#include <map>
#include <memory>
#include <string>
#include <type_traits>

namespace sf::cli {

// The receiver format, one line for every --help that reads receivers.
constexpr const char* kReceiverFormatHelp =
    "Receivers: a float EXR/TIFF with channels u v d [f [ndl]]: u, v in [0, 1] (texel i's centre at (i + 0.5) / W, "
    "v = 0 the map's first row), d the receiver's depth in the map's encoding (or --receiver-encoding), f its "
    "footprint in level-0 texels (default 1), ndl = n.l towards the light (<= 0: faces away, visibility 0); "
    "background: d = NaN.";

// Examples at the foot of the commands whose registration gives none (scene, evaluate,
// evaluate-layouts, coherent and its subcommands), and the top level's pointer to where to
// start: every --help ends with one. Called once every command is registered.
void add_examples(CLI::App& app);

// The terminal's width in columns when stdout is one (at least 40), else 80.
size_t help_width();

// CLI11's formatter with each line wrapped to `width`: an option's or a command's description
// continues under the description column, other lines under their own indentation.
std::shared_ptr<CLI::Formatter> wrapping_formatter(size_t width);

// Wraps one text to `width` columns, continuation lines indented by `indent`.
std::string wrap_line(const std::string& line, size_t width, size_t indent);

// An enum option's values by name: "a|b|c" for its help, the error "must be a, b or c, got 'x'"
// for anything else (case-insensitive).
template <class T>
CLI::Validator named_values(const std::map<std::string, T>& values) {
  std::string names, listed;
  size_t i = 0;
  for (const auto& entry : values) {
    names += (names.empty() ? "" : "|") + entry.first;
    listed += (i == 0 ? "" : (i + 1 == values.size() ? " or " : ", ")) + entry.first;
    ++i;
  }
  CLI::Validator v(
      [values, listed](std::string& text) {
        std::string lower = text;
        for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
        const auto it = values.find(lower);
        if (it == values.end()) return "must be " + listed + ", got '" + text + "'";
        text = std::to_string(static_cast<std::underlying_type_t<T>>(it->second));
        return std::string();
      },
      "", "names");
  return v;
}
// The type name an option with named_values shows: "a|b|c".
template <class T>
std::string value_names(const std::map<std::string, T>& values) {
  std::string names;
  for (const auto& entry : values) names += (names.empty() ? "" : "|") + entry.first;
  return names;
}

}  // namespace sf::cli

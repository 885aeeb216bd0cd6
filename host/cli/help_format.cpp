#include "help_format.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <sstream>
#include <utility>

#include "print.hpp"

namespace sf::cli {
namespace {

class WrappingFormatter : public CLI::Formatter {
 public:
  explicit WrappingFormatter(size_t width) : width_(width) {}
  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
    const std::string text = CLI::Formatter::make_help(app, std::move(name), mode);
    std::istringstream in(text);
    std::string line, out;
    const size_t column = get_column_width();
    while (std::getline(in, line)) {
      size_t indent = line.find_first_not_of(' ');
      if (indent == std::string::npos) indent = 0;
      // A two-column line (an option or a command and its description): continue under the description.
      const bool two_columns = indent >= 2 && line.size() > column && line[column - 1] == ' ' && line[column] != ' ';
      if (two_columns) indent = column;
      // An option's name line running past the width (its exclusions): continue under the name.
      else if (indent == 2 && line.size() > 3 && line[2] == '-')
        indent = 6;
      else if (!two_columns)
        indent = indent == 0 ? 2 : indent + 4;  // a paragraph's or an example's continuation
      out += wrap_line(line, width_, std::min(indent, width_ / 2)) + "\n";
    }
    return out;
  }

 private:
  size_t width_;
};

}  // namespace

size_t help_width() {
  winsize ws{};
  if (stdout_is_terminal() && ::ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 40) return ws.ws_col;
  return 80;
}

std::shared_ptr<CLI::Formatter> wrapping_formatter(size_t width) {
  auto f = std::make_shared<WrappingFormatter>(width);
  f->column_width(30);
  return f;
}

void add_examples(CLI::App& app) {
  const std::pair<const char*, const char*> examples[] = {
      {"scene",
       "Examples:\n  shadowfilter scene spheres -o out/spheres --size 512 --receivers 640x480\n"
       "  shadowfilter scene city -o out/city --layout pssm --cascades 4\n"
       "docs/scenes.md: the files, conventions and built-in scenes"},
      {"evaluate",
       "Examples:\n  shadowfilter evaluate data/spheres data/fence -o out/eval --grid quick\n"
       "  shadowfilter evaluate data/spheres -o out/auto --auto --max-error 0.02\n"
       "docs/results.md: what the figures measure"},
      {"evaluate-layouts",
       "Example:\n  shadowfilter evaluate-layouts city -o out/layouts --frames 4 --receivers 640x360\n"
       "docs/cascades.md"},
      {"coherent",
       "Example:\n  shadowfilter coherent build sphere -o sphere.csm && shadowfilter coherent info sphere.csm"},
  };
  for (const auto& [name, text] : examples)
    for (CLI::App* sub : app.get_subcommands({}))
      if (sub->get_name() == name && sub->get_footer().empty()) sub->footer(text);
  for (CLI::App* coherent : app.get_subcommands({}))
    if (coherent->get_name() == "coherent")
      for (CLI::App* sub : coherent->get_subcommands({}))
        if (sub->get_footer().empty())
          sub->footer(
              "Example:\n  shadowfilter coherent build sphere -o sphere.csm\n"
              "  shadowfilter coherent render sphere.csm --envmap data/envmaps/sky.exr -o sphere.png\n"
              "docs/coherent.md, docs/coherent_render.md");
  // Last: subcommands created after a footer would inherit it.
  app.footer("Start with `shadowfilter filter --help`; your own depth buffers: docs/inputs.md");
}

std::string wrap_line(const std::string& line, size_t width, size_t indent) {
  if (line.size() <= width) return line;
  std::string out;
  std::string rest = line;
  bool first = true;
  while (rest.size() > width) {
    // The last blank at or before `width` after the indentation, else the first one after it.
    const size_t start = first ? rest.find_first_not_of(' ') : indent;
    size_t cut = rest.rfind(' ', width);
    if (cut == std::string::npos || cut <= start) cut = rest.find(' ', width);
    if (cut == std::string::npos) break;
    size_t end = cut;
    while (end > 0 && rest[end - 1] == ' ') --end;
    out += rest.substr(0, end) + "\n";
    const size_t next = rest.find_first_not_of(' ', cut);
    rest = next == std::string::npos ? std::string() : std::string(indent, ' ') + rest.substr(next);
    first = false;
  }
  return out + rest;
}

}  // namespace sf::cli

#include "io_detail.hpp"

namespace sf::io::detail {

std::string one_line(const std::string& text) {
  std::string line;
  line.reserve(text.size());
  bool pending_break = false;
  for (char ch : text) {
    if (ch == '\n' || ch == '\r') {
      pending_break = true;
      continue;
    }
    if (pending_break && !line.empty()) line += "; ";
    pending_break = false;
    line += ch;
  }
  const auto first = line.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const auto last = line.find_last_not_of(" \t;");
  return line.substr(first, last - first + 1);
}

void fail(const std::string& role, const std::string& path, const std::string& problem) {
  throw InputError(role + " '" + one_line(path) + "': " + one_line(problem));
}

// Library messages can run long (libtiff reports every failed strip); the start says enough.
std::string details_suffix(const std::string& details) {
  constexpr size_t kMaxDetails = 240;
  std::string line = one_line(details);
  if (line.empty()) return "";
  if (line.size() > kMaxDetails) line = line.substr(0, kMaxDetails) + "...";
  return " (" + line + ")";
}

}  // namespace sf::io::detail

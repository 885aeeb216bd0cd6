#pragma once
// The lines of a list file (frame lists, light lists): text lines of bounded length, numbered for
// messages. The number of entries is each list's own bound.
#include <cstddef>
#include <istream>
#include <string>
#include <utility>

namespace sf::cli {

// The longest line a list may hold (three paths of PATH_MAX and more fit).
inline constexpr size_t kMaxListLineBytes = 64 * 1024;

class ListLines {
 public:
  // `name`: the list as messages name it (its path).
  ListLines(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}
  // The next line without its line feed; false at the end of the input. InputError "NAME:N: ..."
  // for a line longer than kMaxListLineBytes and for a NUL byte (a path would end there: not a
  // text file).
  bool next(std::string& line);
  // "NAME:N" of the line last returned.
  std::string where() const { return name_ + ":" + std::to_string(number_); }

 private:
  std::istream& in_;
  std::string name_;
  size_t number_ = 0;
};

}  // namespace sf::cli

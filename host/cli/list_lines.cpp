#include "list_lines.hpp"

#include "shadowfilter/errors.hpp"

namespace sf::cli {

bool ListLines::next(std::string& line) {
  line.clear();
  std::streambuf* in = in_.rdbuf();
  using traits = std::char_traits<char>;
  traits::int_type c = in->sbumpc();
  if (traits::eq_int_type(c, traits::eof())) return false;
  ++number_;
  for (; !traits::eq_int_type(c, traits::eof()) && traits::to_char_type(c) != '\n'; c = in->sbumpc()) {
    if (traits::to_char_type(c) == '\0') throw InputError(where() + ": a NUL byte; a list is text, one entry a line");
    if (line.size() == kMaxListLineBytes)
      throw InputError(where() + ": a line longer than " + std::to_string(kMaxListLineBytes) + " bytes");
    line += traits::to_char_type(c);
  }
  return true;
}

}  // namespace sf::cli

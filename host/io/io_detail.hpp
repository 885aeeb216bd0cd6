#pragma once
// Internal helpers shared by the image reader and writer (not part of the public interface).
#include <string>

#include "shadowfilter/errors.hpp"

namespace sf::io::detail {

// Collapses a (possibly multi-line) library message into one line: newlines become "; ",
// surrounding whitespace is trimmed.
std::string one_line(const std::string& text);

// Throws InputError("<role> '<path>': <problem>") with the problem collapsed to one line.
[[noreturn]] void fail(const std::string& role, const std::string& path, const std::string& problem);

// " (<details>)" when details is non-empty, else "": appends a library message to a problem.
std::string details_suffix(const std::string& details);

}  // namespace sf::io::detail

#pragma once
// The commands print through std::cout and std::cerr, never through C's stdio, so that
// sf::cli::run (run.hpp) can hand them the caller's streams.
#include <string>

namespace sf::cli {

// printf's formatting, into a string.
std::string formatted(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace sf::cli

namespace sf::cli {

// Whether what a command prints reaches this process's own stdout / stderr, and that is a
// terminal (progress bars, the help's width): false while run() writes to streams it was handed
// (a test), whatever the process's descriptors are.
bool stdout_is_terminal();
bool stderr_is_terminal();
// run() says whether it writes to the process's std::cout and std::cerr.
void set_process_streams(bool on);

}  // namespace sf::cli

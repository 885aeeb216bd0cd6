#include "print.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdarg>
#include <cstdio>

namespace sf::cli {

std::string formatted(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(n > 0 ? size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

namespace {
std::atomic<bool> process_streams{true};
}  // namespace

bool stdout_is_terminal() { return process_streams && ::isatty(STDOUT_FILENO); }
bool stderr_is_terminal() { return process_streams && ::isatty(STDERR_FILENO); }
void set_process_streams(bool on) { process_streams = on; }

}  // namespace sf::cli

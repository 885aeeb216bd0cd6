#include "io_detail.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

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

std::filesystem::path temporary_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path target(path);
  const std::string name = "." + target.stem().string() + ".tmp." + std::to_string(::getpid()) + "." +
                           std::to_string(counter++) + target.extension().string();
  return target.parent_path() / name;
}

TemporaryFile::~TemporaryFile() {
  if (!path_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
}

void move_into_place(TemporaryFile& temporary, const std::string& path, const std::string& role) {
  std::error_code ec;
  std::filesystem::rename(temporary.path(), path, ec);
  if (ec) fail(role, path, "cannot move the finished file into place (" + ec.message() + ")");
  temporary.release();
}

void write_text_atomically(const std::string& path, const std::string& text, const std::string& role) {
  TemporaryFile temporary(temporary_path_for(path));
  {
    std::ofstream out(temporary.path(), std::ios::binary);
    out << text;
    out.flush();
    if (!out) fail(role, path, "cannot write");
  }
  move_into_place(temporary, path, role);
}

}  // namespace sf::io::detail

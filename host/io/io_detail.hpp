#pragma once
// Internal helpers shared by the image reader and writer (not part of the public interface).
#include <filesystem>
#include <string>
#include <utility>

#include "shadowfilter/errors.hpp"

namespace sf::io::detail {

// Collapses a (possibly multi-line) library message into one line: newlines become "; ",
// surrounding whitespace is trimmed.
std::string one_line(const std::string& text);

// Throws InputError("<role> '<path>': <problem>") with the problem collapsed to one line.
[[noreturn]] void fail(const std::string& role, const std::string& path, const std::string& problem);

// " (<details>)" when details is non-empty, else "": appends a library message to a problem.
std::string details_suffix(const std::string& details);

// Atomic writes: a temporary file in the output's directory, renamed over the output only once it
// is complete, so a failed write never leaves a partial file or clobbers an old one.
// ".<stem>.tmp.<pid>.<n><ext>" next to `path`: same file system (rename stays atomic), the real
// extension last (OIIO picks the format from it), unique per process and per call.
std::filesystem::path temporary_path_for(const std::string& path);

// Removes the temporary file when the write is abandoned (error or exception).
class TemporaryFile {
 public:
  explicit TemporaryFile(std::filesystem::path path) : path_(std::move(path)) {}
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile();
  const std::filesystem::path& path() const { return path_; }
  void release() { path_.clear(); }

 private:
  std::filesystem::path path_;
};

// Renames the finished temporary file over `path` (InputError naming `role` when it cannot).
void move_into_place(TemporaryFile& temporary, const std::string& path, const std::string& role);

}  // namespace sf::io::detail

#pragma once
// Internal helpers shared by the image reader and writer (not part of the public interface).
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <map>
#include <vector>
#include <string>
#include <utility>

#include "shadowfilter/errors.hpp"

namespace sf::io::detail {

// Pixels of subimage 0 converted to float, interleaved, first row of the file first, with the
// header's string attributes.
struct RawImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;
  std::vector<std::string> channel_names;
  std::map<std::string, std::string> attributes;
  OIIO::TypeDesc stored_format;  // the file's (first non-float, if mixed) per-channel type

  float at(size_t texel, int channel) const { return pixels[texel * channels + channel]; }
  size_t texels() const { return static_cast<size_t>(width) * height; }
};

// Reads subimage 0, miplevel 0 as float; InputError("<role> '<path>': ...") when the file is
// missing, not an image, empty, deep or a volume, truncated or corrupt.
RawImage read_raw(const std::string& path, const std::string& role);

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

// Writes a text file atomically (a temporary file, then rename); InputError naming `role`.
void write_text_atomically(const std::string& path, const std::string& text, const std::string& role);

}  // namespace sf::io::detail

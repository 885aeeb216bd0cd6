#pragma once
// Internal helpers shared by the image reader and writer (not part of the public interface).
#include <OpenImageIO/imageio.h>

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

// The image in `spec`'s format (OIIO picks the writer from `path`'s extension), encoded in
// memory; InputError naming `role` and `path` when it cannot be.
std::vector<unsigned char> encode_with_oiio(const std::string& path, const std::string& role,
                                            const OIIO::ImageSpec& spec, OIIO::TypeDesc pixel_type, const void* pixels);

}  // namespace sf::io::detail

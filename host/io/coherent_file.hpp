#pragma once
// The coherent shadow map file (.csm, docs/coherent.md "File format"): a versioned little-endian
// header with the stack layout and the object's source, the offset image and the segments, and
// a CRC-32 of everything before it. Written atomically; a truncated, corrupted or other-version
// file is refused with InputError (one line).
#include <cstdint>
#include <string>

#include "shadowfilter/coherent.hpp"

namespace sf::io {

inline constexpr uint32_t kCoherentFileVersion = 1;

struct CoherentFile {
  coherent::CompressedStack stack;
  std::string source;  // the object: a mesh path as given to `coherent build`, or a built-in name
};

void write_coherent(const std::string& path, const CoherentFile& file);
CoherentFile read_coherent(const std::string& path);

}  // namespace sf::io

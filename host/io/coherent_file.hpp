#pragma once
// The coherent shadow map file (.csm, docs/coherent.md "File format"): a versioned little-endian
// header with the stack layout and the object's source, the offset image and the segments, and
// a CRC-32 of everything before it. Written atomically; a truncated, corrupted or other-version
// file is refused with InputError (one line).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/coherent.hpp"

namespace sf::io {

// Version 2 (written for distant maps): 32-bit view indices, stored in 2 bytes up to 65536 views
// and 4 beyond, then the depths. Version 3 (written for a local light's depth cube maps): version
// 2 with the light after the source (corner, edge a, edge b: 9 doubles; samples a, b and the
// ordering: 3 uint32; far: a double; a mesh light's point count P: uint32, then P points and P
// normals, 6 doubles each, and the area: a double). Version 1 (read): one word per segment,
// (z_avg << 16) | i_last.
inline constexpr uint32_t kCoherentFileVersion = 2;
inline constexpr uint32_t kCoherentLocalVersion = 3;

struct CoherentFile {
  coherent::CompressedStack stack;
  std::string source;  // the object: a mesh path as given to `coherent build`, or a built-in name
  // A local light's cube maps (stack.layout is coherent::cube_layout of it); none: distant maps.
  std::optional<coherent::LocalLight> local;
};

void write_coherent(const std::string& path, const CoherentFile& file);
CoherentFile read_coherent(const std::string& path);

// A part of a stack before its compression (docs/coherent.md "Shards"): the maps of sequence
// positions [first, end) as render_stack renders them, 16-bit z1 and z2 per texel. `coherent build
// --shard K/N` writes one; `coherent merge` reads the parts of a stack, checks that they are one
// layout and object and cover every view once, and compresses the whole. The file (.csmpart):
// magic "SFCSP\r\n\x1a", version, the .csm header's layout and source, first and end, z1 then z2
// (little-endian), CRC-32. Refused like a .csm when truncated, corrupted or of another version.
inline constexpr uint32_t kCoherentPartVersion = 1;

struct CoherentPart {
  coherent::StackLayout layout;
  std::string source;
  uint32_t first = 0, end = 0;
  std::vector<uint16_t> z1, z2;  // (end - first) * layout.texels() each, map after map
};

void write_coherent_part(const std::string& path, const CoherentPart& part);
CoherentPart read_coherent_part(const std::string& path);

}  // namespace sf::io

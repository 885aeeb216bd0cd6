#include "png_header.hpp"

#include <fstream>

#include "io_detail.hpp"

namespace sf::io::detail {

void check_png_chunks(const std::string& path, uint64_t file_bytes, const std::string& role) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(role, path, "cannot open it");
  uint64_t at = 8;  // after the signature
  in.seekg(8);
  for (;;) {
    // A chunk: length (4, big-endian), type (4), data (length), CRC (4).
    if (file_bytes - at < 12) fail(role, path, "truncated: the PNG ends before its IEND chunk");
    unsigned char h[8];
    in.read(reinterpret_cast<char*>(h), 8);
    if (!in) fail(role, path, "cannot read a PNG chunk header");
    const uint64_t length = uint64_t(h[0]) << 24 | uint64_t(h[1]) << 16 | uint64_t(h[2]) << 8 | h[3];
    std::string type(reinterpret_cast<const char*>(h + 4), 4);
    for (char& c : type)
      if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'))) c = '?';
    if (length > 0x7fffffffu || length > file_bytes - at - 12)
      fail(role, path,
           "truncated or corrupt: PNG chunk '" + type + "' declares " + std::to_string(length) +
               " bytes, the file holds " + std::to_string(file_bytes - at - 12) + " after its header");
    if (type == "IEND") return;
    at += 12 + length;
    in.seekg(std::streamoff(at));
  }
}

}  // namespace sf::io::detail

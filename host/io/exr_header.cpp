#include "exr_header.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <utility>
#include <vector>

#include "input_file.hpp"
#include "io_detail.hpp"

namespace sf::io::detail {
namespace {

// Version field flags (OpenEXR file layout): a tiled single part, a multi-part file.
constexpr uint32_t kTiledFlag = 0x200;
constexpr uint32_t kMultiPartFlag = 0x1000;
// Attribute and type names are at most 31 bytes, or 255 with the long-names flag.
constexpr size_t kMaxName = 255;

// Scan lines per chunk of each compression (OpenEXR's Compression enum); unknown ones count as
// the most any has (DWAB), which gives the fewest chunks.
uint64_t lines_per_chunk(int compression) {
  switch (compression) {
    case 0:  // none
    case 1:  // rle
    case 2:  // zips
      return 1;
    case 3:  // zip
    case 5:  // pxr24
      return 16;
    case 4:  // piz
    case 6:  // b44
    case 7:  // b44a
    case 8:  // dwaa
      return 32;
    default:  // dwab and any other
      return 256;
  }
}

struct Part {
  bool has_window = false, has_tiles = false;
  int64_t width = 0, height = 0;
  uint64_t channels = 0;
  int compression = 0;
  uint32_t tile_x = 0, tile_y = 0;
  bool tiled = false;
};

class HeaderReader {
 public:
  HeaderReader(const std::string& path, uint64_t file_bytes, const std::string& role)
      : in_(path, std::ios::binary), path_(path), role_(role), size_(file_bytes) {
    if (!in_) fail(role_, path_, "cannot open it");
  }
  uint64_t at() const { return at_; }
  void read(void* out, uint64_t n, const char* what) {
    if (n > size_ - at_) fail(role_, path_, std::string("truncated or corrupt: the header ends inside ") + what);
    in_.read(static_cast<char*>(out), std::streamsize(n));
    if (!in_) fail(role_, path_, std::string("cannot read the header (") + what + ")");
    at_ += n;
  }
  uint32_t u32(const char* what) {
    unsigned char b[4];
    read(b, 4, what);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  }
  // A NUL-terminated name; "" for the empty name that ends a header.
  std::string name(const char* what) {
    std::string text;
    for (;;) {
      char c = 0;
      read(&c, 1, what);
      if (c == '\0') return text;
      if (text.size() == kMaxName)
        fail(role_, path_, std::string("corrupt header: ") + what + " longer than 255 bytes");
      text += c;
    }
  }
  void skip(uint64_t n, const std::string& attribute) {
    if (n > size_ - at_)
      fail(role_, path_,
           "truncated or corrupt: header attribute '" + one_line(attribute) + "' declares " + std::to_string(n) +
               " bytes, the file holds " + std::to_string(size_ - at_) + " after it");
    in_.seekg(std::streamoff(n), std::ios::cur);
    at_ += n;
  }

 private:
  std::ifstream in_;
  const std::string& path_;
  const std::string& role_;
  uint64_t size_;
  uint64_t at_ = 0;
};

// The bytes of a value of a fixed-size attribute type (OpenEXR 3.1's standard types), -1 for the
// types whose size varies (string, stringvector, floatvector, chlist, preview, and types this walk
// does not know, which OpenEXR reads as opaque bytes of the declared size).
int fixed_size_of(const std::string& type) {
  static const std::pair<const char*, int> sizes[] = {
      {"box2i", 16},
      {"box2f", 16},
      {"chromaticities", 32},
      {"compression", 1},
      {"deepImageState", 1},
      {"double", 8},
      {"envmap", 1},
      {"float", 4},
      {"int", 4},
      {"keycode", 28},
      {"lineOrder", 1},
      {"m33f", 36},
      {"m33d", 72},
      {"m44f", 64},
      {"m44d", 128},
      {"rational", 8},
      {"tiledesc", 9},
      {"timecode", 8},
      {"v2i", 8},
      {"v2f", 8},
      {"v2d", 16},
      {"v3i", 12},
      {"v3f", 12},
      {"v3d", 24},
  };
  for (const auto& [name, bytes] : sizes)
    if (type == name) return bytes;
  return -1;
}

int32_t as_int(uint32_t v) {
  int32_t s = 0;
  std::memcpy(&s, &v, 4);
  return s;
}

// One header's attributes up to its terminating empty name; false for the empty header that
// ends the headers of a multi-part file.
bool read_part(HeaderReader& r, Part& part, bool multi_part, const std::string& path, const std::string& role) {
  bool first = true;
  for (;;) {
    const std::string name = r.name("an attribute name");
    if (name.empty()) return !(multi_part && first);
    first = false;
    const std::string type = r.name("an attribute type");
    const uint32_t declared = r.u32("an attribute size");
    if (as_int(declared) < 0)
      fail(role, path, "corrupt header: attribute '" + one_line(name) + "' declares a negative size");
    // OpenEXR reads a value of a fixed-size type whole, whatever size the attribute declares, and
    // goes on from where that value ends; a preview's pixels and a string vector's strings by the
    // sizes they state inside. A declaration that disagrees would put this walk and OpenEXR's
    // reader at different places (and OpenEXR would allocate what the misread bytes say), so it
    // is refused.
    const int fixed = fixed_size_of(type);
    if (fixed >= 0 && declared != uint32_t(fixed))
      fail(role, path,
           "corrupt header: attribute '" + one_line(name) + "' of type " + one_line(type) + " declares " +
               std::to_string(declared) + " bytes, the type has " + std::to_string(fixed));
    if (name == "dataWindow" && type == "box2i" && declared == 16) {
      const int64_t x0 = as_int(r.u32("dataWindow")), y0 = as_int(r.u32("dataWindow"));
      const int64_t x1 = as_int(r.u32("dataWindow")), y1 = as_int(r.u32("dataWindow"));
      if (x1 < x0 || y1 < y0)
        fail(role, path,
             "corrupt header: an empty or inverted data window (" + std::to_string(x0) + ", " + std::to_string(y0) +
                 ") - (" + std::to_string(x1) + ", " + std::to_string(y1) + ")");
      part.width = x1 - x0 + 1;
      part.height = y1 - y0 + 1;
      part.has_window = true;
    } else if (name == "compression" && type == "compression" && declared == 1) {
      unsigned char c = 0;
      r.read(&c, 1, "compression");
      part.compression = c;
    } else if (name == "tiles" && type == "tiledesc" && declared == 9) {
      part.tile_x = r.u32("tiles");
      part.tile_y = r.u32("tiles");
      r.skip(1, name);
      part.has_tiles = true;
    } else if (name == "type" && type == "string") {
      std::string value(declared <= 64 ? declared : 0, '\0');
      if (declared <= 64)
        r.read(value.data(), declared, "type");
      else
        r.skip(declared, name);
      part.tiled = value == "tiledimage";
    } else if (type == "preview") {  // width, height, then 4 bytes a pixel
      if (declared < 8) fail(role, path, "corrupt header: preview attribute '" + one_line(name) + "' under 8 bytes");
      const uint64_t w = r.u32("preview"), h = r.u32("preview");
      if (w * h > (uint64_t(declared) - 8) / 4 || 8 + 4 * w * h != declared)
        fail(role, path,
             "corrupt header: preview attribute '" + one_line(name) + "' of " + std::to_string(w) + "x" +
                 std::to_string(h) + " pixels declares " + std::to_string(declared) + " bytes");
      r.skip(declared - 8, name);
    } else if (type == "stringvector") {  // strings, each a length and its bytes
      const uint64_t end = r.at() + declared;
      while (r.at() < end) {
        if (end - r.at() < 4)
          fail(role, path, "corrupt header: string vector '" + one_line(name) + "' ends inside a length");
        const uint32_t n = r.u32("a string length");
        if (as_int(n) < 0 || n > end - r.at())
          fail(role, path,
               "corrupt header: a string of string vector '" + one_line(name) + "' runs past the attribute");
        r.skip(n, name);
      }
    } else if (name == "channels" && type == "chlist") {
      // Entries: a name, then 16 bytes (type, pLinear, reserved, x and y sampling); an empty name ends it.
      const uint64_t end = r.at() + declared;
      while (r.at() < end) {
        if (r.name("a channel name").empty()) break;
        r.skip(16, name);
        ++part.channels;
      }
      if (r.at() != end) fail(role, path, "corrupt header: the channel list does not fill its attribute");
    } else {
      r.skip(declared, name);
    }
  }
}

// The fewest chunks the part's pixels take: tiles of level 0 (mip and rip levels add more), or
// groups of scan lines.
uint64_t fewest_chunks(const Part& part) {
  if (part.tiled && part.tile_x > 0 && part.tile_y > 0) {
    const uint64_t across = (uint64_t(part.width) + part.tile_x - 1) / part.tile_x;
    const uint64_t down = (uint64_t(part.height) + part.tile_y - 1) / part.tile_y;
    uint64_t chunks = 0;
    return multiply_fits(across, down, &chunks) ? chunks : UINT64_MAX;
  }
  const uint64_t lines = lines_per_chunk(part.compression);
  return (uint64_t(part.height) + lines - 1) / lines;
}

}  // namespace

void check_exr_header(const std::string& path, uint64_t file_bytes, const std::string& role) {
  HeaderReader r(path, file_bytes, role);
  r.skip(4, "magic");
  const uint32_t version = r.u32("the version");
  const bool multi_part = (version & kMultiPartFlag) != 0;
  std::vector<Part> parts;
  for (;;) {
    Part part;
    part.tiled = !multi_part && (version & kTiledFlag) != 0;
    if (!read_part(r, part, multi_part, path, role)) break;
    parts.push_back(part);
    if (!multi_part) break;
  }
  uint64_t chunks = 0;
  for (const Part& part : parts) {
    if (!part.has_window) fail(role, path, "corrupt header: no dataWindow");
    uint64_t texels = 0, floats = 0;
    if (!multiply_fits(uint64_t(part.width), uint64_t(part.height), &texels) ||
        !multiply_fits(texels, std::max<uint64_t>(part.channels, 1), &floats) || floats > UINT64_MAX / 4)
      floats = UINT64_MAX / 4;
    require_within_image_budget(floats * 4,
                                "the header's " + std::to_string(part.width) + "x" + std::to_string(part.height) +
                                    " image of " + std::to_string(part.channels) +
                                    (part.channels == 1 ? " channel" : " channels"),
                                path, role);
    const uint64_t part_chunks = fewest_chunks(part);
    chunks = part_chunks > UINT64_MAX - chunks ? UINT64_MAX : chunks + part_chunks;
  }
  // Each chunk has an 8-byte offset right after the headers, then at least its own header.
  const uint64_t table_bytes = chunks > UINT64_MAX / 8 ? UINT64_MAX : chunks * 8;
  if (table_bytes > file_bytes - r.at())
    fail(role, path,
         "truncated or corrupt: the header needs " + std::to_string(chunks) + " chunks (" +
             std::to_string(table_bytes) + " bytes of offsets), the file holds " + std::to_string(file_bytes - r.at()) +
             " bytes after its header");
}

}  // namespace sf::io::detail

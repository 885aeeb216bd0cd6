#include "coherent_file.hpp"

#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "input_file.hpp"
#include "io_detail.hpp"
#include "output_file.hpp"

namespace sf::io {
namespace {

using detail::fail;

const char* const kInputRole = "coherent shadow map";
const char* const kOutputRole = "output coherent shadow map";
// "SFCSM", then CR LF SUB: a file that went through a text-mode transfer fails the magic.
const unsigned char kMagic[8] = {'S', 'F', 'C', 'S', 'M', '\r', '\n', 0x1a};
// The largest source string read back (a path).
constexpr uint32_t kMaxSource = 4096;

class Writer {
 public:
  void u32(uint32_t v) {
    for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<unsigned char>(v >> (8 * b)));
  }
  void u64(uint64_t v) {
    for (int b = 0; b < 8; ++b) bytes.push_back(static_cast<unsigned char>(v >> (8 * b)));
  }
  void f64(double v) {
    uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    u64(bits);
  }
  void raw(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    bytes.insert(bytes.end(), p, p + n);
  }
  std::vector<unsigned char> bytes;
};

class Reader {
 public:
  Reader(const std::vector<unsigned char>& b, const std::string& path) : bytes_(b), path_(path) {}
  void need(size_t n, const char* what) const {
    if (bytes_.size() - at_ < n) fail(kInputRole, path_, std::string("truncated (ends inside the ") + what + ")");
  }
  uint32_t u32(const char* what) {
    need(4, what);
    uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= uint32_t(bytes_[at_ + b]) << (8 * b);
    at_ += 4;
    return v;
  }
  uint64_t u64(const char* what) {
    need(8, what);
    uint64_t v = 0;
    for (int b = 0; b < 8; ++b) v |= uint64_t(bytes_[at_ + b]) << (8 * b);
    at_ += 8;
    return v;
  }
  double f64(const char* what) {
    const uint64_t bits = u64(what);
    double v = 0.0;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  std::string str(uint32_t n, const char* what) {
    need(n, what);
    std::string s(bytes_.begin() + long(at_), bytes_.begin() + long(at_ + n));
    at_ += n;
    return s;
  }
  size_t at() const { return at_; }

 private:
  const std::vector<unsigned char>& bytes_;
  std::string path_;
  size_t at_ = 0;
};

uint32_t crc32_of(const unsigned char* data, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (n > 0) {  // zlib takes a uInt length
    const uInt chunk = n > (1u << 30) ? (1u << 30) : uInt(n);
    crc = crc32(crc, data, chunk);
    data += chunk;
    n -= chunk;
  }
  return uint32_t(crc);
}

// Every texel's segments end at the last view, with increasing i_last (what a lookup relies on).
void check_segments(const coherent::CompressedStack& c, const std::string& path) {
  const size_t texels = c.layout.texels();
  const uint32_t last = uint32_t(c.layout.views() - 1);
  if (c.offsets[0] != 0) fail(kInputRole, path, "corrupted: the first offset is not 0");
  for (size_t t = 0; t < texels; ++t) {
    const uint32_t begin = c.offsets[t], end = c.offsets[t + 1];
    if (end <= begin || end > c.segments.size())
      fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + " has no segments or runs past the end");
    for (uint32_t s = begin + 1; s < end; ++s)
      if ((c.segments[s] & coherent::kSegmentIndexMask) <= (c.segments[s - 1] & coherent::kSegmentIndexMask))
        fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + "'s segments are out of order");
    if ((c.segments[end - 1] & coherent::kSegmentIndexMask) != last)
      fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + "'s segments do not reach the last view");
  }
}

}  // namespace

void write_coherent(const std::string& path, const CoherentFile& file) {
  const coherent::CompressedStack& c = file.stack;
  coherent::validate(c.layout);
  if (c.offsets.size() != c.layout.texels() + 1 || c.offsets.back() != c.segments.size())
    fail(kOutputRole, path, "the offsets do not match the layout and segments");
  Writer w;
  w.raw(kMagic, sizeof kMagic);
  w.u32(kCoherentFileVersion);
  w.u32(uint32_t(c.layout.resolution));
  w.u32(uint32_t(c.layout.views_theta));
  w.u32(uint32_t(c.layout.views_phi));
  w.u32(uint32_t(c.layout.ordering));
  w.u32(uint32_t(c.layout.depth_pair));
  w.u32(uint32_t(c.layout.far_plane));
  for (int axis = 0; axis < 3; ++axis) w.f64(c.layout.center[axis]);
  w.f64(c.layout.radius);
  w.u64(c.segments.size());
  w.u32(uint32_t(file.source.size()));
  w.raw(file.source.data(), file.source.size());
  for (uint32_t v : c.offsets) w.u32(v);
  for (uint32_t v : c.segments) w.u32(v);
  w.u32(crc32_of(w.bytes.data(), w.bytes.size()));

  write_file(path, kOutputRole, w.bytes.data(), w.bytes.size());
}

namespace {

CoherentFile read_coherent_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(kInputRole, path, "cannot open (" + std::string(std::strerror(errno)) + ")");
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    fail(kInputRole, path, "not a coherent shadow map (bad magic)");
  Reader r(bytes, path);
  r.str(sizeof kMagic, "magic");
  const uint32_t version = r.u32("header");
  if (version != kCoherentFileVersion)
    fail(kInputRole, path,
         "version " + std::to_string(version) + ", this build reads version " + std::to_string(kCoherentFileVersion));
  if (bytes.size() < 4 + r.at()) fail(kInputRole, path, "truncated (ends inside the header)");
  const uint32_t stored_crc = uint32_t(bytes[bytes.size() - 4]) | uint32_t(bytes[bytes.size() - 3]) << 8 |
                              uint32_t(bytes[bytes.size() - 2]) << 16 | uint32_t(bytes[bytes.size() - 1]) << 24;

  CoherentFile file;
  coherent::StackLayout& l = file.stack.layout;
  l.resolution = int(r.u32("header"));
  l.views_theta = int(r.u32("header"));
  l.views_phi = int(r.u32("header"));
  l.ordering = coherent::Ordering(r.u32("header"));
  l.depth_pair = coherent::DepthPair(r.u32("header"));
  l.far_plane = coherent::FarPlane(r.u32("header"));
  for (int axis = 0; axis < 3; ++axis) l.center[axis] = r.f64("header");
  l.radius = r.f64("header");
  const uint64_t segments = r.u64("header");
  const uint32_t source_size = r.u32("header");
  if (source_size > kMaxSource)
    fail(kInputRole, path, "corrupted: a source name of " + std::to_string(source_size) + " bytes");
  file.source = r.str(source_size, "header");
  try {
    coherent::validate(l);
  } catch (const InputError& e) {
    fail(kInputRole, path, std::string("corrupted header: ") + e.what());
  }
  // The data after the header: the offsets, the segments (a count the file states, any number up
  // to 2^64 - 1, so it is checked against the bytes there are before any product is formed) and
  // the CRC.
  const uint64_t offsets_bytes = 4 * (uint64_t(l.texels()) + 1);  // texels <= 4096^2 (validate)
  const uint64_t after_header = bytes.size() - r.at();
  if (after_header < offsets_bytes + 4 || segments > (after_header - offsets_bytes - 4) / 4)
    fail(kInputRole, path,
         "truncated: " + std::to_string(bytes.size()) + " bytes, the header announces " + std::to_string(segments) +
             " segments for " + std::to_string(l.texels()) + " texels");
  const uint64_t expected = r.at() + offsets_bytes + 4 * segments + 4;
  if (bytes.size() > expected)
    fail(kInputRole, path, "corrupted: " + std::to_string(bytes.size() - expected) + " bytes past the end of the data");
  if (crc32_of(bytes.data(), bytes.size() - 4) != stored_crc) fail(kInputRole, path, "corrupted (CRC-32 mismatch)");
  file.stack.offsets.resize(l.texels() + 1);
  for (uint32_t& v : file.stack.offsets) v = r.u32("offsets");
  file.stack.segments.resize(size_t(segments));
  for (uint32_t& v : file.stack.segments) v = r.u32("segments");
  if (file.stack.offsets.back() != segments)
    fail(kInputRole, path, "corrupted: the offsets do not end at the segment count");
  check_segments(file.stack, path);
  return file;
}

}  // namespace

// Only a regular file; its bytes are read whole (a regular file's size is what it holds).
CoherentFile read_coherent(const std::string& path) {
  require_regular_file(path, kInputRole);
  record_input(path);
  return with_out_of_memory_named(path, kInputRole, [&] { return read_coherent_bytes(path); });
}

}  // namespace sf::io

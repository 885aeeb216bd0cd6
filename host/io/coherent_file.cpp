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
  void u16(uint16_t v) {
    bytes.push_back(static_cast<unsigned char>(v));
    bytes.push_back(static_cast<unsigned char>(v >> 8));
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
  uint16_t u16(const char* what) {
    need(2, what);
    const uint16_t v = uint16_t(bytes_[at_] | bytes_[at_ + 1] << 8);
    at_ += 2;
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
    if (end <= begin || end > c.last.size())
      fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + " has no segments or runs past the end");
    for (uint32_t s = begin + 1; s < end; ++s)
      if (c.last[s] <= c.last[s - 1])
        fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + "'s segments are out of order");
    if (c.last[end - 1] != last)
      fail(kInputRole, path, "corrupted: texel " + std::to_string(t) + "'s segments do not reach the last view");
  }
}

void put_layout(Writer& w, const coherent::StackLayout& l) {
  w.u32(uint32_t(l.resolution));
  w.u32(uint32_t(l.views_theta));
  w.u32(uint32_t(l.views_phi));
  w.u32(uint32_t(l.ordering));
  w.u32(uint32_t(l.depth_pair));
  w.u32(uint32_t(l.far_plane));
  for (int axis = 0; axis < 3; ++axis) w.f64(l.center[axis]);
  w.f64(l.radius);
}

coherent::StackLayout get_layout(Reader& r) {
  coherent::StackLayout l;
  l.resolution = int(r.u32("header"));
  l.views_theta = int(r.u32("header"));
  l.views_phi = int(r.u32("header"));
  l.ordering = coherent::Ordering(r.u32("header"));
  l.depth_pair = coherent::DepthPair(r.u32("header"));
  l.far_plane = coherent::FarPlane(r.u32("header"));
  for (int axis = 0; axis < 3; ++axis) l.center[axis] = r.f64("header");
  l.radius = r.f64("header");
  return l;
}

// The file's bytes after its magic and version are checked: InputError naming `role`.
std::vector<unsigned char> read_versioned(const std::string& path, const char* role, const unsigned char* magic,
                                          std::initializer_list<uint32_t> versions, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(role, path, "cannot open (" + std::string(std::strerror(errno)) + ")");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 8 || std::memcmp(bytes.data(), magic, 8) != 0)
    fail(role, path, std::string("not a ") + what + " (bad magic)");
  if (bytes.size() < 12) fail(role, path, "truncated (ends inside the header)");
  const uint32_t v =
      uint32_t(bytes[8]) | uint32_t(bytes[9]) << 8 | uint32_t(bytes[10]) << 16 | uint32_t(bytes[11]) << 24;
  if (std::find(versions.begin(), versions.end(), v) == versions.end()) {
    std::string known;
    size_t k = 0;
    for (uint32_t version : versions)
      known += (k++ == 0 ? "" : k == versions.size() ? " and " : ", ") + std::to_string(version);
    fail(role, path, "version " + std::to_string(v) + ", this build reads version " + known);
  }
  return bytes;
}

uint32_t stored_crc(const std::vector<unsigned char>& bytes) {
  const size_t n = bytes.size();
  return uint32_t(bytes[n - 4]) | uint32_t(bytes[n - 3]) << 8 | uint32_t(bytes[n - 2]) << 16 |
         uint32_t(bytes[n - 1]) << 24;
}

}  // namespace

void write_coherent(const std::string& path, const CoherentFile& file) {
  const coherent::CompressedStack& c = file.stack;
  coherent::validate(c.layout);
  if (c.offsets.size() != c.layout.texels() + 1 || c.offsets.back() != c.last.size() || c.depth.size() != c.last.size())
    fail(kOutputRole, path, "the offsets do not match the layout and segments");
  Writer w;
  w.bytes.reserve(c.compressed_bytes() + 256 + file.source.size());
  if (file.local) {
    coherent::validate(*file.local);
    if (c.layout.views_theta != 6 || c.layout.views_phi != file.local->count())
      fail(kOutputRole, path, "a local light's stack holds 6 maps per sampling point");
  }
  w.raw(kMagic, sizeof kMagic);
  w.u32(file.local ? kCoherentLocalVersion : kCoherentFileVersion);
  put_layout(w, c.layout);
  w.u64(c.last.size());
  w.u32(uint32_t(file.source.size()));
  w.raw(file.source.data(), file.source.size());
  if (file.local) {
    const coherent::LocalLight& l = *file.local;
    for (const Vec3& v : {l.corner, l.edge_a, l.edge_b})
      for (int axis = 0; axis < 3; ++axis) w.f64(v[axis]);
    w.u32(uint32_t(l.samples_a));
    w.u32(uint32_t(l.samples_b));
    w.u32(uint32_t(l.ordering));
    w.f64(l.far);
    w.u32(uint32_t(l.points.size()));
    for (size_t k = 0; k < l.points.size(); ++k)
      for (const Vec3& v : {l.points[k], l.normals[k]})
        for (int axis = 0; axis < 3; ++axis) w.f64(v[axis]);
    if (l.is_mesh()) w.f64(l.area);
  }
  for (uint32_t v : c.offsets) w.u32(v);
  const bool wide = coherent::index_bytes(c.layout) == 4;
  for (uint32_t v : c.last) wide ? w.u32(v) : w.u16(uint16_t(v));
  for (uint16_t v : c.depth) w.u16(v);
  w.u32(crc32_of(w.bytes.data(), w.bytes.size()));

  write_file(path, kOutputRole, w.bytes.data(), w.bytes.size());
}

namespace {

CoherentFile read_coherent_bytes(const std::string& path) {
  const std::vector<unsigned char> bytes =
      read_versioned(path, kInputRole, kMagic, {1, kCoherentFileVersion, kCoherentLocalVersion}, "coherent shadow map");
  Reader r(bytes, path);
  r.str(sizeof kMagic, "magic");
  const uint32_t version = r.u32("header");
  if (bytes.size() < 4 + r.at()) fail(kInputRole, path, "truncated (ends inside the header)");
  const uint32_t crc = stored_crc(bytes);

  CoherentFile file;
  coherent::StackLayout& l = file.stack.layout;
  l = get_layout(r);
  const uint64_t segments = r.u64("header");
  const uint32_t source_size = r.u32("header");
  if (source_size > kMaxSource)
    fail(kInputRole, path, "corrupted: a source name of " + std::to_string(source_size) + " bytes");
  file.source = r.str(source_size, "header");
  if (version == kCoherentLocalVersion) {
    coherent::LocalLight light;
    for (Vec3* v : {&light.corner, &light.edge_a, &light.edge_b})
      for (int axis = 0; axis < 3; ++axis) (*v)[axis] = r.f64("header");
    light.samples_a = int(std::min<uint32_t>(r.u32("header"), 1u << 30));
    light.samples_b = int(std::min<uint32_t>(r.u32("header"), 1u << 30));
    light.ordering = coherent::Ordering(r.u32("header"));
    light.far = r.f64("header");
    const uint32_t points = r.u32("header");
    if (points > uint32_t(coherent::kMaxLightSamples))
      fail(kInputRole, path, "corrupted header: a mesh light of " + std::to_string(points) + " sampling points");
    r.need(size_t(points) * 48, "header");
    light.points.resize(points);
    light.normals.resize(points);
    for (uint32_t k = 0; k < points; ++k)
      for (Vec3* v : {&light.points[k], &light.normals[k]})
        for (int axis = 0; axis < 3; ++axis) (*v)[axis] = r.f64("header");
    if (points > 0) light.area = r.f64("header");
    try {
      coherent::validate(light);
    } catch (const InputError& e) {
      fail(kInputRole, path, std::string("corrupted header: ") + e.what());
    }
    if (l.views_theta != 6 || l.views_phi != light.count())
      fail(kInputRole, path, "corrupted header: a local light's stack holds 6 maps per sampling point");
    file.local = light;
  }
  try {
    coherent::validate(l);
  } catch (const InputError& e) {
    fail(kInputRole, path, std::string("corrupted header: ") + e.what());
  }
  if (version == 1 && l.views() > 65536)  // version 1 packs a 16-bit index with the depth
    fail(kInputRole, path, "corrupted header: " + std::to_string(l.views()) + " views in a version 1 file");
  // The data after the header: the offsets, the segments (a count the file states, any number up
  // to 2^64 - 1, so it is checked against the bytes there are before any product is formed) and
  // the CRC. Version 1: one word per segment, (z_avg << 16) | i_last; version 2: the indices
  // (index_bytes each), then the depths (2 bytes each).
  const uint64_t segment_bytes = version == 1 ? 4 : 2 + uint64_t(coherent::index_bytes(l));
  const uint64_t offsets_bytes = 4 * (uint64_t(l.texels()) + 1);  // texels <= 4096^2 (validate)
  const uint64_t after_header = bytes.size() - r.at();
  if (after_header < offsets_bytes + 4 || segments > (after_header - offsets_bytes - 4) / segment_bytes)
    fail(kInputRole, path,
         "truncated: " + std::to_string(bytes.size()) + " bytes, the header announces " + std::to_string(segments) +
             " segments for " + std::to_string(l.texels()) + " texels");
  const uint64_t expected = r.at() + offsets_bytes + segment_bytes * segments + 4;
  if (bytes.size() > expected)
    fail(kInputRole, path, "corrupted: " + std::to_string(bytes.size() - expected) + " bytes past the end of the data");
  if (crc32_of(bytes.data(), bytes.size() - 4) != crc) fail(kInputRole, path, "corrupted (CRC-32 mismatch)");
  file.stack.offsets.resize(l.texels() + 1);
  for (uint32_t& v : file.stack.offsets) v = r.u32("offsets");
  file.stack.last.resize(size_t(segments));
  file.stack.depth.resize(size_t(segments));
  if (version == 1) {
    for (size_t s = 0; s < segments; ++s) {
      const uint32_t word = r.u32("segments");
      file.stack.last[s] = word & 0xffffu;
      file.stack.depth[s] = uint16_t(word >> 16);
    }
  } else {
    const bool wide = coherent::index_bytes(l) == 4;
    for (uint32_t& v : file.stack.last) v = wide ? r.u32("segments") : r.u16("segments");
    for (uint16_t& v : file.stack.depth) v = r.u16("segments");
  }
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

namespace {

const char* const kPartRole = "coherent stack part";
const char* const kPartOutputRole = "output coherent stack part";
const unsigned char kPartMagic[8] = {'S', 'F', 'C', 'S', 'P', '\r', '\n', 0x1a};

CoherentPart read_part_bytes(const std::string& path) {
  const std::vector<unsigned char> bytes =
      read_versioned(path, kPartRole, kPartMagic, {kCoherentPartVersion}, "coherent stack part");
  Reader r(bytes, path);
  r.str(sizeof kPartMagic, "magic");
  r.u32("header");  // the version
  CoherentPart part;
  part.layout = get_layout(r);
  const uint32_t source_size = r.u32("header");
  if (source_size > kMaxSource)
    fail(kPartRole, path, "corrupted: a source name of " + std::to_string(source_size) + " bytes");
  part.source = r.str(source_size, "header");
  part.first = r.u32("header");
  part.end = r.u32("header");
  try {
    coherent::validate(part.layout);
  } catch (const InputError& e) {
    fail(kPartRole, path, std::string("corrupted header: ") + e.what());
  }
  if (part.first >= part.end || part.end > uint32_t(part.layout.views()))
    fail(kPartRole, path,
         "corrupted: views " + std::to_string(part.first) + ".." + std::to_string(part.end) + " of a stack of " +
             std::to_string(part.layout.views()));
  const uint64_t values = uint64_t(part.end - part.first) * part.layout.texels();  // < 2^16 views x 2^24 texels
  const uint64_t expected = r.at() + 4 * values + 4;
  if (bytes.size() < expected)
    fail(kPartRole, path,
         "truncated: " + std::to_string(bytes.size()) + " bytes, the header announces " + std::to_string(expected));
  if (bytes.size() > expected)
    fail(kPartRole, path, "corrupted: " + std::to_string(bytes.size() - expected) + " bytes past the end of the data");
  if (crc32_of(bytes.data(), bytes.size() - 4) != stored_crc(bytes))
    fail(kPartRole, path, "corrupted (CRC-32 mismatch)");
  const unsigned char* p = bytes.data() + r.at();  // z1, then z2
  for (std::vector<uint16_t>* z : {&part.z1, &part.z2}) {
    z->resize(size_t(values));
    for (uint16_t& v : *z) {
      v = uint16_t(p[0] | p[1] << 8);
      p += 2;
    }
  }
  // The stack's invariant, on which the compression relies: z1 < z2, or both kNoSurface.
  for (size_t i = 0; i < part.z1.size(); ++i)
    if (!(part.z1[i] < part.z2[i] || (part.z1[i] == coherent::kNoSurface && part.z2[i] == coherent::kNoSurface)))
      fail(kPartRole, path, "corrupted: texel value " + std::to_string(i) + " has z1 >= z2");
  return part;
}

}  // namespace

void write_coherent_part(const std::string& path, const CoherentPart& part) {
  coherent::validate(part.layout);
  const size_t values = size_t(part.end - part.first) * part.layout.texels();
  if (part.first >= part.end || part.end > uint32_t(part.layout.views()) || part.z1.size() != values ||
      part.z2.size() != values)
    fail(kPartOutputRole, path, "the maps do not match the layout and view range");
  Writer w;
  w.raw(kPartMagic, sizeof kPartMagic);
  w.u32(kCoherentPartVersion);
  put_layout(w, part.layout);
  w.u32(uint32_t(part.source.size()));
  w.raw(part.source.data(), part.source.size());
  w.u32(part.first);
  w.u32(part.end);
  w.bytes.reserve(w.bytes.size() + 4 * values + 4);
  for (const std::vector<uint16_t>* z : {&part.z1, &part.z2})
    for (uint16_t v : *z) {
      w.bytes.push_back(static_cast<unsigned char>(v));
      w.bytes.push_back(static_cast<unsigned char>(v >> 8));
    }
  w.u32(crc32_of(w.bytes.data(), w.bytes.size()));
  write_file(path, kPartOutputRole, w.bytes.data(), w.bytes.size());
}

CoherentPart read_coherent_part(const std::string& path) {
  require_regular_file(path, kPartRole);
  record_input(path);
  return with_out_of_memory_named(path, kPartRole, [&] { return read_part_bytes(path); });
}

}  // namespace sf::io

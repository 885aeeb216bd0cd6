#include "program_cache.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

#include "atomic_file.hpp"

namespace sf::detail {
namespace {

constexpr char kMagic[8] = {'S', 'F', 'P', 'R', 'O', 'G', '0', '1'};
// A device binary larger than this is no entry of ours (PoCL's are kilobytes to a few megabytes).
constexpr uint64_t kMaxBinaryBytes = uint64_t(1) << 30;
constexpr uint32_t kMaxKeyBytes = 4096;

uint64_t fnv1a(const unsigned char* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out += char((v >> (8 * i)) & 0xff);
}

uint64_t get_u64(const std::string& in, size_t at) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(static_cast<unsigned char>(in[at + i])) << (8 * i);
  return v;
}

}  // namespace

std::string pack_cache_entry(const std::string& key, const std::vector<unsigned char>& binary) {
  std::string entry(kMagic, sizeof kMagic);
  put_u64(entry, key.size());
  entry += key;
  put_u64(entry, binary.size());
  put_u64(entry, fnv1a(binary.data(), binary.size()));
  entry.append(binary.begin(), binary.end());
  return entry;
}

bool unpack_cache_entry(const std::string& entry, const std::string& key, std::vector<unsigned char>* binary,
                        std::string* problem) {
  size_t at = sizeof kMagic;
  if (entry.size() < at + 8 || std::memcmp(entry.data(), kMagic, sizeof kMagic) != 0) {
    *problem = "not a cache entry (no header)";
    return false;
  }
  const uint64_t key_size = get_u64(entry, at);
  at += 8;
  if (key_size > kMaxKeyBytes || entry.size() - at < key_size + 16) {
    *problem = "truncated header";
    return false;
  }
  if (entry.compare(at, key_size, key) != 0 || key_size != key.size()) {
    *problem = "built for another key";
    return false;
  }
  at += key_size;
  const uint64_t size = get_u64(entry, at);
  const uint64_t checksum = get_u64(entry, at + 8);
  at += 16;
  if (size > kMaxBinaryBytes || entry.size() - at != size) {
    *problem = "length " + std::to_string(entry.size() - at) + " bytes, the header says " + std::to_string(size);
    return false;
  }
  const auto* data = reinterpret_cast<const unsigned char*>(entry.data()) + at;
  if (size == 0 || fnv1a(data, size) != checksum) {
    *problem = "checksum mismatch";
    return false;
  }
  binary->assign(data, data + size);
  return true;
}

bool read_cache_entry(const std::string& path, const std::string& key, std::vector<unsigned char>* binary,
                      std::string* problem) {
  problem->clear();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    if (errno != ENOENT) *problem = std::string("cannot open (") + std::strerror(errno) + ")";
    return false;
  }
  struct stat st {};
  std::string entry;
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && uint64_t(st.st_size) <= kMaxBinaryBytes + kMaxKeyBytes + 64;
  if (!ok) *problem = "not a regular file of a plausible size";
  if (ok) {
    entry.resize(size_t(st.st_size));
    size_t done = 0;
    while (done < entry.size()) {
      const ssize_t n = ::read(fd, &entry[done], entry.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += size_t(n);
    }
    entry.resize(done);
  }
  ::close(fd);
  return ok && unpack_cache_entry(entry, key, binary, problem);
}

std::string write_cache_entry(const std::string& path, const std::string& key,
                              const std::vector<unsigned char>& binary) {
  const std::string entry = pack_cache_entry(key, binary);
  try {
    write_file_atomically(path, entry.data(), entry.size(), Durability::Volatile);
  } catch (const FileWriteError& e) {
    return e.what();
  }
  return "";
}

}  // namespace sf::detail

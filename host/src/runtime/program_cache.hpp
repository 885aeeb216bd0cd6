#pragma once
// The on-disk program cache's entries. An entry is a header (a magic string, the key it was built
// for, the length and an FNV-1a checksum of the binary) and the device binary. A reader takes only
// an entry that verifies: a file truncated or zeroed by a crash or a full disk, a binary of another
// key (two driver versions, a swapped file) or anything else is discarded and the program rebuilt.
// Entries are written through the atomic writer (atomic_file.hpp), so concurrent writers never
// expose a half-written entry.
#include <string>
#include <vector>

namespace sf::detail {

// The whole entry for `binary` built under `key`.
std::string pack_cache_entry(const std::string& key, const std::vector<unsigned char>& binary);

// The binary of `entry` when it is an intact entry for `key`; else false and `problem` says why.
bool unpack_cache_entry(const std::string& entry, const std::string& key, std::vector<unsigned char>* binary,
                        std::string* problem);

// Reads the entry at `path` for `key`. Returns false with an empty `problem` when there is none,
// false with a problem when the file is there but does not verify (the caller discards it).
bool read_cache_entry(const std::string& path, const std::string& key, std::vector<unsigned char>* binary,
                      std::string* problem);

// Writes the entry (no fsync: a torn entry fails its checksum). Returns "" or the reason it failed;
// a cache that cannot be written never fails a run.
std::string write_cache_entry(const std::string& path, const std::string& key,
                              const std::vector<unsigned char>& binary);

}  // namespace sf::detail

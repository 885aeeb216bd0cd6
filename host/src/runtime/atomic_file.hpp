#pragma once
// The one way shadowfilter puts a file on disk (outputs, previews, result files, .csm files, the
// program cache): the bytes go to a temporary file beside the destination (the same file system,
// so the rename is atomic), every write, the flush and the close are checked, the data reaches the
// disk (fsync) where it matters, and the rename comes last. A failure at any step removes the
// temporary file and leaves an earlier file at the destination as it was.
//
// Temporary files and partial directories are listed while they exist, so that an interrupted
// process can remove them (remove_unfinished_files, called by the CLI's signal watcher).
#include <cstddef>
#include <stdexcept>
#include <string>

namespace sf::detail {

// A write that failed: the step and the system's reason ("no space left on device"), without
// the path (the caller names the file in its own terms).
class FileWriteError : public std::runtime_error {
 public:
  FileWriteError(const std::string& what, int error_number) : std::runtime_error(what), error_number_(error_number) {}
  int error_number() const { return error_number_; }

 private:
  int error_number_;
};

// Durable: fsync the file before the rename and the directory after it (outputs a user keeps).
// Volatile: no fsync (a cache entry that verifies itself when read).
enum class Durability { Durable, Volatile };

// A finished file at a temporary path beside its destination, not yet in place: the constructor
// writes it whole (FileWriteError when it cannot), commit() renames it over the destination, and
// the destructor removes it if it was never committed.
class StagedFile {
 public:
  StagedFile(std::string destination, const void* data, size_t size, Durability durability = Durability::Durable);
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  void commit();
  const std::string& destination() const { return destination_; }
  const std::string& temporary() const { return temporary_; }

 private:
  std::string destination_, temporary_;
  Durability durability_;
};

// StagedFile and commit in one call.
void write_file_atomically(const std::string& destination, const void* data, size_t size,
                           Durability durability = Durability::Durable);

// ".<name>.tmp.<pid>.<n><ext>" beside `destination`: unique per process and call, the real
// extension last (image writers that pick a format from the name still see it).
std::string temporary_path_beside(const std::string& destination);

// Paths to remove if the process is interrupted: a temporary file, or a partial directory (removed
// with its contents). Registered before they are created, unregistered once they are in place or
// gone.
void register_unfinished(const std::string& path);
void unregister_unfinished(const std::string& path);
// Removes every registered path and returns how many it removed. Ending: the registry stays
// locked afterwards, so no new temporary file starts (the caller is about to end the process, and
// a thread that tries to start one waits for the end); Continuing: it is unlocked again.
enum class AfterRemoval { Ending, Continuing };
size_t remove_unfinished_files(AfterRemoval after) noexcept;

}  // namespace sf::detail

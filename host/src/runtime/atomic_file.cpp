#include "atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <system_error>

namespace sf::detail {
namespace {

namespace fs = std::filesystem;

std::string reason(int error_number) { return std::strerror(error_number); }

[[noreturn]] void fail(const std::string& step, int error_number) {
  throw FileWriteError(step + " (" + reason(error_number) + ")", error_number);
}

struct UnfinishedRegistry {
  std::mutex mutex;
  std::set<std::string> paths;
};

UnfinishedRegistry& registry() {
  static UnfinishedRegistry* r = new UnfinishedRegistry;  // never destroyed: a signal may come during exit
  return *r;
}

// The file a destination names: a symbolic link's target (the link stays a link, its file is
// replaced), else the path itself. A directory, a device, a FIFO or a socket is refused: the
// rename would replace the node itself.
std::string resolve_destination(const std::string& destination) {
  struct stat st {};
  if (::lstat(destination.c_str(), &st) != 0) {
    if (errno == ENOENT) return destination;
    fail("cannot look at the destination", errno);
  }
  std::string path = destination;
  if (S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const fs::path target = fs::canonical(destination, ec);
    if (ec) {
      // A link to a file not written yet: its target's directory must exist.
      const fs::path weak = fs::weakly_canonical(destination, ec);
      if (ec) fail("cannot follow the symbolic link", ec.value());
      return weak.string();
    }
    path = target.string();
    if (::stat(path.c_str(), &st) != 0) fail("cannot look at the link's target", errno);
  }
  if (S_ISDIR(st.st_mode)) throw FileWriteError("is a directory", EISDIR);
  if (!S_ISREG(st.st_mode)) throw FileWriteError("exists and is not a regular file (a device, FIFO or socket)", EINVAL);
  return path;
}

void write_all(int fd, const void* data, size_t size) {
  const char* at = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, at, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed", errno);
    }
    if (n == 0) fail("write failed", EIO);
    at += n;
    size -= size_t(n);
  }
}

void sync_directory(const std::string& file) {
  std::string dir = fs::path(file).parent_path().string();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: some file systems cannot open or sync a directory
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

std::string temporary_path_beside(const std::string& destination) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(destination);
  const std::string name = "." + target.stem().string() + ".tmp." + std::to_string(::getpid()) + "." +
                           std::to_string(counter++) + target.extension().string();
  return (target.parent_path() / name).string();
}

StagedFile::StagedFile(std::string destination, const void* data, size_t size, Durability durability)
    : destination_(resolve_destination(destination)), durability_(durability) {
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    temporary_ = temporary_path_beside(destination_);
    register_unfinished(temporary_);
    fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) break;
    const int error = errno;
    unregister_unfinished(temporary_);
    temporary_.clear();
    // EEXIST: a leftover of an earlier process with this pid; the next name is free.
    if (error != EEXIST || attempt >= 16) fail("cannot create a temporary file beside it", error);
  }
  try {
    write_all(fd, data, size);
    if (durability_ == Durability::Durable && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
      fail("write failed while flushing to disk", errno);
  } catch (...) {
    ::close(fd);
    ::unlink(temporary_.c_str());
    unregister_unfinished(temporary_);
    temporary_.clear();
    throw;
  }
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temporary_.c_str());
    unregister_unfinished(temporary_);
    temporary_.clear();
    fail("write failed when closing", error);
  }
}

StagedFile::~StagedFile() {
  if (temporary_.empty()) return;
  ::unlink(temporary_.c_str());
  unregister_unfinished(temporary_);
}

void StagedFile::commit() {
  if (temporary_.empty()) throw FileWriteError("nothing to move into place", EINVAL);
  if (::rename(temporary_.c_str(), destination_.c_str()) != 0) {
    const int error = errno;
    fail("cannot move the finished file into place", error);  // the destructor removes the temporary
  }
  unregister_unfinished(temporary_);
  temporary_.clear();
  if (durability_ == Durability::Durable) sync_directory(destination_);
}

void write_file_atomically(const std::string& destination, const void* data, size_t size, Durability durability) {
  StagedFile file(destination, data, size, durability);
  file.commit();
}

void register_unfinished(const std::string& path) {
  UnfinishedRegistry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.paths.insert(path);
}

void unregister_unfinished(const std::string& path) {
  UnfinishedRegistry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.paths.erase(path);
}

size_t remove_unfinished_files(AfterRemoval after) noexcept {
  UnfinishedRegistry& r = registry();
  r.mutex.lock();
  size_t removed = 0;
  for (const std::string& path : r.paths) {
    std::error_code ec;
    removed += fs::remove_all(path, ec) > 0 ? 1 : 0;
  }
  if (after == AfterRemoval::Continuing) {
    r.paths.clear();
    r.mutex.unlock();
  }
  return removed;
}

}  // namespace sf::detail

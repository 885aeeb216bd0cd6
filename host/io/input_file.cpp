#include "input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "io_detail.hpp"

namespace sf::io {
namespace {

using detail::fail;

std::string stat_problem(int error) {
  switch (error) {
    case ENOENT:
      return "file not found";
    case ELOOP:
      return "too many levels of symbolic links (a symlink loop)";
    case EACCES:
      return "permission denied";
    case ENOTDIR:
      return "a component of the path is not a directory";
    case ENAMETOOLONG:
      return "the path is too long";
    default:
      return std::strerror(error);
  }
}

std::string type_problem(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISFIFO(mode)) return "is a FIFO (named pipe), not a regular file";
  if (S_ISCHR(mode)) return "is a character device, not a regular file";
  if (S_ISBLK(mode)) return "is a block device, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

// The physical memory in bytes (0 when the system does not say).
uint64_t physical_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page_size = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page_size <= 0) return 0;
  uint64_t bytes = 0;
  return multiply_fits(uint64_t(pages), uint64_t(page_size), &bytes) ? bytes : UINT64_MAX;
}

// Without a physical memory figure: 4 GiB, enough for a 16384^2 map of four float channels.
constexpr uint64_t kFallbackBudget = uint64_t(4) << 30;

std::string budget_origin() {
  return std::getenv(kImageBudgetVariable)
             ? std::string("set by ") + kImageBudgetVariable
             : std::string("a quarter of physical memory; set ") + kImageBudgetVariable + " to change it";
}

}  // namespace

uint64_t require_regular_file(const std::string& path, const std::string& role) {
  if (path.empty()) fail(role, path, "no file named (an empty path)");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail(role, path, stat_problem(errno));
  if (!S_ISREG(st.st_mode)) fail(role, path, type_problem(st.st_mode));
  // A regular file opens at once; O_NONBLOCK keeps that true should it be replaced meanwhile.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail(role, path, stat_problem(errno));
  ::close(fd);
  return uint64_t(st.st_size);
}

uint64_t image_memory_budget() {
  if (const char* text = std::getenv(kImageBudgetVariable)) {
    const std::string digits(text);
    errno = 0;
    const unsigned long long value = std::strtoull(text, nullptr, 10);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || errno == ERANGE || value == 0)
      throw InputError(std::string(kImageBudgetVariable) + "='" + detail::one_line(digits) +
                       "' is not a positive whole number of bytes");
    return value;
  }
  const uint64_t memory = physical_memory();
  return memory == 0 ? kFallbackBudget : memory / 4;
}

void require_within_image_budget(uint64_t bytes, const std::string& what, const std::string& path,
                                 const std::string& role) {
  const uint64_t budget = image_memory_budget();
  if (bytes <= budget) return;
  fail(role, path,
       what + " takes " + std::to_string(bytes) + " bytes as float, over the memory budget of " +
           std::to_string(budget) + " bytes (" + budget_origin() + ")");
}

bool multiply_fits(uint64_t a, uint64_t b, uint64_t* product) { return !__builtin_mul_overflow(a, b, product); }

}  // namespace sf::io

#pragma once
// What every reader checks before it reads a file (images, .csm, frame and light lists,
// environment maps, meshes), and the memory a declared size may claim. Every failure is an
// InputError("<role> '<path>': <problem>") on one line.
#include <cstdint>
#include <new>
#include <string>

#include "shadowfilter/errors.hpp"

namespace sf::io {

// Only regular files are read. The file's type comes from stat() before anything opens it, so a
// FIFO or a device (/dev/zero) can neither hang a reader nor feed it without end. Each case has
// its own problem: "file not found", "is a directory", "too many levels of symbolic links (a
// symlink loop)", "is a FIFO (named pipe)", "is a character device", "is a block device", "is a
// socket", "permission denied", "a component of the path is not a directory". Returns the
// file's size in bytes.
uint64_t require_regular_file(const std::string& path, const std::string& role);

// The environment variable that sets the image memory budget, in bytes.
inline constexpr const char* kImageBudgetVariable = "SHADOWFILTER_MAX_IMAGE_BYTES";

// The most bytes the pixels of one input image may take once decoded to float: a quarter of the
// physical memory (the run holds the pixels, their conversion and the device's copies at once),
// or SHADOWFILTER_MAX_IMAGE_BYTES when set (a positive whole number of bytes; InputError when it
// is anything else).
uint64_t image_memory_budget();

// InputError("<role> '<path>': <what> takes N bytes ..., over the memory budget of M bytes (...;
// set SHADOWFILTER_MAX_IMAGE_BYTES to change it)") when `bytes` exceeds image_memory_budget().
void require_within_image_budget(uint64_t bytes, const std::string& what, const std::string& path,
                                 const std::string& role);

// a * b, or false when the product does not fit 64 bits (declared sizes are checked with it).
bool multiply_fits(uint64_t a, uint64_t b, uint64_t* product);

// Runs `read` (a reader's body); std::bad_alloc becomes InputError("<role> '<path>': out of
// memory while reading it"), so a file that asks for more than the machine has is named.
template <class Read>
auto with_out_of_memory_named(const std::string& path, const std::string& role, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw InputError(role + " '" + path + "': out of memory while reading it");
  }
}

}  // namespace sf::io

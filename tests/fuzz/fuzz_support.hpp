#pragma once
// What every harness shares: the input written to a scratch file (the readers take paths), a
// small image memory budget, and the rule a harness checks: a parser may refuse its input only
// with sf::InputError. Any other exception escapes LLVMFuzzerTestOneInput and ends the run as a
// crash (so does every sanitizer report under libFuzzer).
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "input_file.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::fuzz {

// One directory per process under TMPDIR (or /tmp), removed at exit.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path d =
        std::filesystem::path(tmp && *tmp ? tmp : "/tmp") / ("sf_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch_dir(), ignored);
    });
    return d;
  }();
  return dir;
}

// Writes the input to the scratch file `name` and returns its path.
inline std::string write_input(const uint8_t* data, size_t size, const std::string& name) {
  const std::string path = (scratch_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

// Once per process: images of at most 1 MiB as float (a header may claim anything; what a
// harness should find is a wrong check, not the machine's memory, and the seeds are a few KiB),
// OpenImageIO on this thread.
inline void setup() {
  static const bool done = [] {
    ::setenv(io::kImageBudgetVariable, "1048576", 0);
    OIIO::attribute("threads", 1);
    OIIO::attribute("exr_threads", 1);
    return true;
  }();
  (void)done;
}

// Runs one parse: a refusal (InputError) is an answer, anything else escapes.
template <class Parse>
void refusals_allowed(Parse&& parse) {
  try {
    parse();
  } catch (const InputError&) {
  }
}

}  // namespace sf::fuzz

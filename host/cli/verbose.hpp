#pragma once
// -v / --verbose of the commands that build OpenCL programs: the compiler's warnings about the
// library's kernels, which are off otherwise (Runtime::set_compiler_warnings) because they say
// nothing about the user's input.
#include <CLI/CLI.hpp>

#include "shadowfilter/runtime.hpp"

namespace sf::cli {

void add_verbose_flag(CLI::App& cmd, bool& verbose);
// With verbose: warnings on, and each program's build log printed to stderr as it is built
// (programs from the binary cache were built before and print nothing).
void apply_verbose(Runtime& rt, bool verbose);

}  // namespace sf::cli

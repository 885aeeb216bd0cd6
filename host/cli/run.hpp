#pragma once
// The command line in process: `shadowfilter ARGS...` as a function. main.cpp is a thin wrapper
// that adds what belongs to a process (the signal watcher, SIGXFSZ ignored); tests and other
// programs call run() directly.
#include <ostream>
#include <string>
#include <vector>

namespace sf::cli {

// Parses `args` (without the program's name), runs the command and returns its exit code: 0 ok,
// 2 bad input, 3 OpenCL failure, 1 anything else; every exception becomes one line on `err`.
// What the command prints goes to `out` and `err`: std::cout and std::cerr are redirected to
// them for the call, so one run at a time per process. The guard that no output replaces a file
// read (io::guard_inputs_read) is on for the call and off, its files forgotten, afterwards.
int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sf::cli

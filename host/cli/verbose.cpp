#include "verbose.hpp"

#include <iostream>

#include "print.hpp"

namespace sf::cli {

void add_verbose_flag(CLI::App& c, bool& verbose) {
  c.add_flag("-v,--verbose", verbose,
             "Print the OpenCL compiler's warnings about the kernels built in this run (kernels from the "
             "binary cache were built before: SHADOWFILTER_CACHE_DIR= with no value disables it) and notes "
             "about the cache (an entry that did not verify, discarded and rebuilt)");
}

void apply_verbose(Runtime& rt, bool verbose) {
  if (!verbose) return;
  rt.set_compiler_warnings(true);
  rt.set_notice_sink([](const std::string& note) { std::cerr << formatted("shadowfilter: %s\n", note.c_str()); });
  rt.set_build_log_sink([](const std::string& files, const std::string& log) {
    std::cerr << formatted("shadowfilter: OpenCL build log of [%s]:\n%s%s", files.c_str(), log.c_str(),
                           log.empty() || log.back() == '\n' ? "" : "\n");
  });
}

}  // namespace sf::cli

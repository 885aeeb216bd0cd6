// A consumer of the core library alone (tests/package): the public headers compile with this
// program's own opencl.hpp settings, and the library answers without any other dependency.
#include <cstdio>

#include "shadowfilter/embed.hpp"
#include "shadowfilter/pipeline.hpp"

int main() {
  sf::FilterOptions opt;  // esm by default
  const sf::KernelPrelude p = sf::kernel_prelude(opt);
  const bool ok = p.files.size() == 4 && p.source.find("sf_visibility") != std::string::npos &&
                  p.build_options.find("-DSF_STORAGE=0") != std::string::npos && !sf::kernel_files().empty();
  std::printf("consumer: %zu kernel files, prelude of %zu bytes: %s\n", sf::kernel_files().size(),
              p.source.size(), ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}

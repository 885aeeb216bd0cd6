#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {

CLI::App* add_methods_command(CLI::App& app, MethodsArgs&) {
  return app.add_subcommand("methods", "List filtering methods, their parameters and memory per texel");
}

int run_methods(const MethodsArgs&) {
  for (const auto& m : methods()) {
    FilterOptions o;  // defaults
    o.method = m.name;
    std::cout << m.name << ": " << m.summary << "\n    parameters: " << m.parameters;
    if (m.raw_depth) {
      std::cout << "\n    memory: no basis images (tests the float32 depth map, 4 bytes per texel)\n";
      continue;
    }
    std::ostringstream mem;
    const int ch = m.channels(o);
    for (const StorageLimit& l : m.storages) {
      o.storage = l.storage;
      mem << (mem.tellp() > 0 ? ", " : "") << storage_name(l.storage) << " " << basis_bytes_per_texel(m, o);
      if (!l.limit.empty()) mem << " (" << l.limit << ")";
    }
    std::cout << "\n    basis: " << ch << " channel(s)";
    if (!m.channels_note.empty()) std::cout << " with the defaults (" << m.channels_note << " in general)";
    std::cout << "; bytes per texel by --storage: " << mem.str() << " (twice that while prefiltering)\n";
    if (m.sat_limit)
      std::cout << "    --lookup sat: refused past a limit on exp(c (zmax - zmin)) that follows the map's depth range "
                   "and size (docs/numerics.md, \"Lookup limits\")\n";
  }
  return 0;
}

}  // namespace sf::cli

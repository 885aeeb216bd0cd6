#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {

CLI::App* add_methods_command(CLI::App& app, MethodsArgs& a) {
  CLI::App* c = app.add_subcommand("methods", "List filtering methods, their parameters and memory per texel");
  c->add_flag("--json", a.json, "Print the methods as a JSON array");
  c->footer("Example:\n  shadowfilter methods\n  shadowfilter filter ... --method vsm --blur-radius 3");
  return c;
}

namespace {

nlohmann::json methods_json() {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& m : methods()) {
    FilterOptions o;
    o.method = m.name;
    nlohmann::json j{{"name", m.name}, {"summary", m.summary}, {"parameters", m.parameters}};
    nlohmann::json defaults = nlohmann::json::object();
    for (const MethodParameter& p : m.parameter_values(o)) defaults[p.key] = p.value;
    j["defaults"] = defaults;
    if (m.raw_depth) {
      j["bytes_per_texel"] = {{"depth", 4}};
    } else {
      j["channels"] = m.channels(o);
      nlohmann::json bytes = nlohmann::json::object();
      for (const StorageLimit& l : m.storages) {
        o.storage = l.storage;
        bytes[storage_name(l.storage)] = basis_bytes_per_texel(m, o);
      }
      j["bytes_per_texel"] = bytes;
    }
    list.push_back(j);
  }
  return list;
}

}  // namespace

int run_methods(const MethodsArgs& a) {
  if (a.json) {
    std::cout << methods_json().dump() << "\n";
    return 0;
  }
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

#include <cmath>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"

namespace sf::cli {

CLI::App* add_methods_command(CLI::App& app, MethodsArgs& a) {
  CLI::App* c = app.add_subcommand("methods", "List filtering methods, their parameters and memory per texel");
  c->add_flag("--json", a.json, "Print the methods as a JSON array");
  c->footer("Example:\n  shadowfilter methods\n  shadowfilter filter ... --method vsm --blur-radius 3");
  return c;
}

namespace {

// The method's flags, generated from its declarations: its own parameters, then the knobs it
// reads ("--esm-c C (default 120; a positive number), --esm-classify ...").
std::string parameters_line(const MethodDesc& m) {
  std::string line;
  auto add = [&line](const Parameter& p) { line += (line.empty() ? "" : ", ") + p.usage(); };
  for (const Parameter& p : m.parameters) add(p);
  // A knob whose default the method resolves shows its flag only: the method's value is on the
  // defaults line.
  for (const std::string& field : m.reads)
    for (const Parameter& k : filter_parameters())
      if (k.field == field)
        line += (line.empty() ? "" : ", ") + (std::isnan(k.default_value) ? k.flag + " " + k.metavar : k.usage());
  return line.empty() ? "none" : line;
}

nlohmann::json methods_json() {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& m : methods()) {
    FilterOptions o;
    o.method = m;
    nlohmann::json j{{"name", m.name}, {"summary", m.summary}, {"parameters", parameters_line(m)}};
    nlohmann::json defaults = nlohmann::json::object();
    for (const MethodParameter& p : m.parameter_values(o)) defaults[p.key] = p.value;
    defaults["normal_offset"] = normal_offset(o);  // texels, where the receivers carry normals
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
    o.method = m;
    std::cout << m.name << ": " << m.summary << "\n    parameters: " << parameters_line(m);
    std::cout << "\n    defaults:";
    for (const MethodParameter& p : m.parameter_values(o)) std::cout << " " << p.key << "=" << parameter_text(p.value);
    std::cout << " normal_offset=" << parameter_text(normal_offset(o));  // texels, with receivers' nx ny nz
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

#include <iostream>

#include "commands.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {

CLI::App* add_methods_command(CLI::App& app, MethodsArgs&) {
  return app.add_subcommand("methods", "List filtering methods, their parameters and memory per texel");
}

int run_methods(const MethodsArgs&) {
  for (const auto& m : methods()) {
    std::cout << m.name << ": " << m.summary << "\n    parameters: " << m.parameters
              << "\n    basis: " << m.channels << " channel(s), " << m.channels * 4
              << " bytes per texel in float32\n";
  }
  return 0;
}

}  // namespace sf::cli

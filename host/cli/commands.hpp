#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "shadowfilter/options.hpp"

namespace sf::cli {

struct DevicesArgs {};
CLI::App* add_devices_command(CLI::App& app, DevicesArgs& args);
int run_devices(const DevicesArgs& args);

struct MethodsArgs {};
CLI::App* add_methods_command(CLI::App& app, MethodsArgs& args);
int run_methods(const MethodsArgs& args);

struct FilterArgs {
  std::string shadow_map, receivers, receiver_depth, output, device;
  std::string encoding = "linear", nonfinite = "error";
  double near_plane = 0.1, far_plane = 100.0;
  bool quiet = false;
  FilterOptions options;
};
CLI::App* add_filter_command(CLI::App& app, FilterArgs& args);
int run_filter(const FilterArgs& args);

}  // namespace sf::cli

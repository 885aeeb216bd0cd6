#pragma once
#include <CLI/CLI.hpp>

#include <limits>
#include <string>
#include <vector>

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
  std::string flags_out;  // --flags-out: ESM classification mask (1 = flagged)
  FilterOptions options;
};
CLI::App* add_filter_command(CLI::App& app, FilterArgs& args);
int run_filter(const FilterArgs& args);

struct SceneArgs {
  std::string scene, out_dir, receivers = "1920x1080", light = "ortho";
  int map_size = 2048, samples = 64, threads = 0;
  unsigned seed = 1;
  std::vector<double> light_dir, light_pos;
  double fov = 0.0;
  double light_size = std::numeric_limits<double>::quiet_NaN();  // NaN: the scene's default
  bool quiet = false;
};
CLI::App* add_scene_command(CLI::App& app, SceneArgs& args);
int run_scene(const SceneArgs& args);

}  // namespace sf::cli

#pragma once
#include <CLI/CLI.hpp>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <memory>

#include "depth_inputs.hpp"
#include "image_io.hpp"
#include "layout_eval.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {

struct DevicesArgs {
  bool json = false;  // --json: the list as a JSON array
};
CLI::App* add_devices_command(CLI::App& app, DevicesArgs& args);
int run_devices(const DevicesArgs& args);

struct MethodsArgs {
  bool json = false;  // --json: the methods as a JSON array
};
CLI::App* add_methods_command(CLI::App& app, MethodsArgs& args);
int run_methods(const MethodsArgs& args);

// --auto (options_auto.cpp): pick the fastest configuration under an error bound on this input.
struct AutoArgs {
  bool enabled = false;
  double max_error = 0.05;
  std::string metric = "p99";
  std::string methods = "all";
  int runs = 3;
  int rounds = 5;                    // interleaved re-measurements of the candidates under the bound
  double tolerance = 0.05;           // least tie band (the measured noise widens it); the cheaper estimate wins
  double sref_bias = 1.0 / 32768.0;  // depth bias of s_ref (eval::kDefaultSrefBias)
};
void add_auto_options(CLI::App& cmd, AutoArgs& args);
// --auto-rounds and --auto-tolerance (how the measured candidates are compared), for `filter`
// (through add_auto_options) and `evaluate`.
void add_auto_choice_options(CLI::App& cmd, AutoArgs& args);

struct FilterArgs {
  std::vector<std::string> shadow_maps;  // one map, or several with --output-dir (a batch)
  std::string receivers, receiver_depth, output, device;
  std::string frames, output_dir;  // batch: --frames LIST, or --shadow-map A B ... --output-dir DIR
  bool keep_going = false;         // batch: report a failed frame and carry on
  std::string shard;               // batch: --shard K/N, the frames this process runs (frame_list.hpp)
  std::string preview = "none";    // --preview [plain|shaded]: pictures beside each output (preview_images.hpp)
  DepthInputArgs inputs;           // encodings, --light, receivers from a camera (depth_inputs.hpp)
  bool quiet = false, verbose = false, json = false;
  std::string flags_out;  // --flags-out: ESM classification mask (1 = flagged)
  // Layered maps (filter_layered.cpp): --cascades DIR|LIST, --view FILE, --cascade-blend B
  // (NaN: the files' own band).
  std::string cascades, view;
  double cascade_blend = std::numeric_limits<double>::quiet_NaN();
  FilterOptions options;
  AutoArgs auto_args;
};
// With --auto: measures the candidates on (depth, receivers), prints what it chose and skipped,
// and returns the chosen options (options_auto.cpp).
FilterOptions choose_auto_options(const FilterArgs& args, const HostImage& depth, const Receivers& receivers,
                                  const std::shared_ptr<Runtime>& runtime);
CLI::App* add_filter_command(CLI::App& app, FilterArgs& args);
int run_filter(const FilterArgs& args);
// The batch (filter_batch.cpp): --frames LIST or --output-dir; the exit code is the number of
// failed frames with --keep-going (at most 125), else 0 (a failure without it throws).
int run_filter_batch(const FilterArgs& args);
// filter --cascades: the layered maps of a cascade set onto a camera view (filter_layered.cpp).
int run_filter_layered(const FilterArgs& args);
// `receivers` (cmd_receivers.cpp): receivers from a camera's depth buffer and a light.
struct ReceiversArgs {
  DepthInputArgs inputs;  // --camera, --camera-depth, --camera-depth-kind, --normals, --light
  std::string output, shadow_map, map_size;
  int threads = 0;
  bool quiet = false, json = false;
};
CLI::App* add_receivers_command(CLI::App& app, ReceiversArgs& args);
int run_receivers(const ReceiversArgs& args);

struct SceneArgs {
  std::string scene, out_dir, receivers = "1920x1080", light = "ortho";
  int map_size = 2048, samples = 64, threads = 0;
  unsigned seed = 1;
  std::vector<double> light_dir, light_pos;
  double fov = std::numeric_limits<double>::quiet_NaN();  // NaN: fitted
  std::vector<double> light_size;                         // --light-size L or W,H; empty: the scene's default
  std::string soft_reference;                             // centre | pixel; empty: the scene's default
  bool quiet = false;
  // Camera and path (NaN / empty: the scene's default; CLI numbers are finite, finite_numbers.hpp).
  std::vector<double> camera_pos, camera_look, camera_to;
  double camera_fov = std::numeric_limits<double>::quiet_NaN();
  double camera_near = std::numeric_limits<double>::quiet_NaN();
  double camera_far = std::numeric_limits<double>::quiet_NaN();
  int frames = 1;
  std::string camera_path = "walk";
  double orbit_degrees = std::numeric_limits<double>::quiet_NaN();
  // Cascade layout ("" = none; 0 / NaN: the layout's default).
  std::string layout;
  int cascades = 0;
  double split_lambda = std::numeric_limits<double>::quiet_NaN();
  double tsm_focus = std::numeric_limits<double>::quiet_NaN();
  double cascade_blend = std::numeric_limits<double>::quiet_NaN();
  bool no_stabilize = false;
  bool cascades_given = false;
};
CLI::App* add_scene_command(CLI::App& app, SceneArgs& args);
int run_scene(const SceneArgs& args);

struct EvaluateArgs {
  std::vector<std::string> dirs;
  std::string methods = "all", grid = "quick", out_dir, device, pareto_metric = "rmse";
  // The plots' reference: soft | hard | target | self; "" = soft, or the reference a prefixed
  // --pareto-metric names ("hard_rmse").
  std::string pareto_reference;
  int target_blur_radius = 3;          // the target filter of the "target" reference
  std::string target_lookup = "mips";  // bilinear | mips | sat
  int runs = 5, warmup = 1;
  bool quiet = false, no_images = false, verbose = false;
  bool frames = false;  // --frames: the dirs are consecutive frames (eval::EvaluationRequest::frames)
  AutoArgs auto_args;
  int auto_radius = 3;               // --auto target: Gaussian radius
  std::string auto_lookup = "auto";  // --auto target lookup: auto | bilinear | mips | sat
};
CLI::App* add_evaluate_command(CLI::App& app, EvaluateArgs& args);
int run_evaluate(const EvaluateArgs& args);

// `evaluate-layouts` (cmd_evaluate_layouts.cpp): layouts x cascade counts x methods on scenes.
struct EvaluateLayoutsArgs {
  std::vector<std::string> scenes;
  std::string out_dir, layouts = "single,pssm,tsm,pssm+tsm", cascade_counts = "4", methods = "pcf,esm,vsm";
  std::string lookup = "mips", receivers = "1920x1080";
  bool quiet = false, verbose = false;
  eval::LayoutEvalRequest request;
};
CLI::App* add_evaluate_layouts_command(CLI::App& app, EvaluateLayoutsArgs& args);
int run_evaluate_layouts(EvaluateLayoutsArgs& args);

// `coherent` (cmd_coherent.cpp): its subcommands, each with the function that runs it.
struct CoherentCommands {
  CLI::App* app = nullptr;
  std::vector<std::pair<CLI::App*, std::function<int()>>> subcommands;
};
void add_coherent_command(CLI::App& app, CoherentCommands& out);
int run_coherent(const CoherentCommands& commands);
// `coherent render` and `coherent sky` (coherent_render.cpp, docs/coherent_render.md): added to
// the `coherent` group with their run functions.
void add_coherent_render_commands(CLI::App& coherent, CoherentCommands& out);

}  // namespace sf::cli

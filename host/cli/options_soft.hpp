#pragma once
// `shadowfilter soft`: soft shadows from area lights (docs/soft.md).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

#include "commands.hpp"
#include "depth_inputs.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::cli {

struct SoftArgs {
  std::string method = "pcss", shadow_map, receivers, receiver_depth, lights, output, device;
  std::string light_type;          // "" = from the shadow map header
  std::vector<double> light_size;  // --light-size L (a square) or W,H (a rectangle); empty: the header's
  double light_near = std::numeric_limits<double>::quiet_NaN(), light_far = std::numeric_limits<double>::quiet_NaN(),
         light_fov = std::numeric_limits<double>::quiet_NaN(), light_extent = std::numeric_limits<double>::quiet_NaN();
  std::string lookup = "sat";
  std::string cssm_storage = "f32";  // --cssm-storage: SoftOptions::cssm.storage by name
  std::vector<float> sharpen;
  bool quiet = false, verbose = false, json = false;
  DepthInputArgs inputs;    // encodings, --light, receivers from a camera (depth_inputs.hpp)
  std::string frames;       // --frames LIST: a batch (soft_batch.cpp)
  bool keep_going = false;  // batch: report a failed frame and carry on
  std::string shard;        // batch: --shard K/N, the frames this process runs (frame_list.hpp)
  SoftOptions options;
  // --auto (soft_auto.cpp): its bound, metric (rmse by default), candidate methods ("soft" by
  // default), runs and rounds; the target is --reference, the grid --auto-grid.
  AutoArgs auto_args{false, 0.05, "rmse", "soft"};
  std::string reference, auto_grid = "default";
  // Layered maps (soft_layered.cpp): --cascades DIR|LIST, --view FILE, --cascade-blend B and the
  // world depth of the light's plane along its axis, --light-plane D (NaN: layer 0's header).
  std::string cascades, view;
  double cascade_blend = std::numeric_limits<double>::quiet_NaN();
  double light_plane = std::numeric_limits<double>::quiet_NaN();
};
CLI::App* add_soft_command(CLI::App& app, SoftArgs& args);
int run_soft(const SoftArgs& args);
// One light's inputs: its map, the light from the map's header with the command line's overrides,
// and its receivers (the image, or when `receivers` is empty the planar `receiver_depth`).
SoftLightInput load_soft_light(const std::string& shadow_map, const std::string& receivers,
                               const std::string& receiver_depth, const SoftArgs& overrides);
// One frame's light and inputs: the map and receivers as load_frame reads them (decoded as
// stated, receivers from a camera where the frame names one), the light from files.light's
// projection when given, else from the map's header. The warnings about the inputs
// (fit_warnings) are added to `warnings` when given, else dropped.
SoftLightInput load_soft_frame(const FrameFiles& files, const SoftArgs& args,
                               std::vector<std::string>* warnings = nullptr);

// The options of --method, --lookup, --cssm-sharpen and the rest (the light comes per map).
SoftOptions soft_options(const SoftArgs& args);
// --auto's options on the soft command (soft_auto.cpp).
void add_soft_auto_options(CLI::App& cmd, SoftArgs& args);
// `soft --auto`: the fastest configuration of evaluate's soft grid (from `base`: the light and the
// knobs the grid does not vary) whose error against --reference stays under --max-error on this
// light's map and receivers (eval::choose_soft_auto). Prints what it chose and why unless quiet
// or JSON (then `summary` gets it); InputError when no configuration meets the bound.
SoftOptions choose_soft_auto_options(const SoftArgs& args, const SoftLightInput& light, const SoftOptions& base,
                                     const std::shared_ptr<Runtime>& runtime, nlohmann::json& summary);
// `soft --frames LIST`: one frame a line as `filter --frames` reads it, each map's light from its
// header; the exit code is the number of failed frames with --keep-going (at most 125).
int run_soft_batch(const SoftArgs& args);

// The light of a shadow map: its EXR header (light_type, near, far, ortho_extents, fov_degrees,
// light_size and, for a rectangular light, light_height; written by `shadowfilter scene`),
// overridden by the command line (--light-size sets both sides).
SoftLight light_from_header(const std::string& shadow_map, const SoftArgs& overrides);

// The area light of a cascade set's layers: its sides as light_from_header reads them
// (--light-size, else layer 0's header light_size and light_height, world units) and the world
// depth of its plane along the light's axis (--light-plane, else the header's light_plane, which
// `scene` writes). InputError naming the file when either is missing or not a finite number.
struct LayeredLight {
  double size = 0.0, height = -1.0;  // height < 0: a square
  double plane = 0.0;
};
LayeredLight layered_light_from_header(const std::string& layer0, const SoftArgs& args);
// `soft --cascades DIR|LIST --view VIEW -o OUT`: a soft method per layer of a cascade set under one
// area light, reconstructed at the camera view's receivers (filter_layered of SoftOptions).
int run_soft_layered(const SoftArgs& args);

}  // namespace sf::cli

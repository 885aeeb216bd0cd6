#pragma once
// `shadowfilter evaluate-layouts` (Oliveira 2009): shadow-map layouts (single, pssm, tsm,
// pssm+tsm) x cascade counts x methods at equal total texels, on a scene seen along a camera path,
// measured against the ray-traced references of every frame. The scene is rendered in process
// (Embree): the camera view and its references once per frame, the layers of every layout per
// frame; each layout is filtered by the layered pipeline (layered.hpp).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::eval {

// One layout of the comparison: its kind, layer count and stabilisation; the layer size follows
// from the total texels.
struct LayoutConfig {
  LayoutKind kind = LayoutKind::Single;
  int cascades = 1;
  bool stabilize = true;
  int layer_size = 0;
  std::string label() const;  // "single", "pssm4", "pssm4 unstable", "tsm", "pssm4+tsm"
};

// Layer side for `layers` layers of equal total texels with one map of side `total_size`:
// total_size / sqrt(layers), rounded to a multiple of 8 (4096 -> 4 x 2048, 2 x 2896).
int equal_texel_side(int total_size, int layers);

struct LayoutEvalRequest {
  std::vector<std::string> scenes;  // built-in names or mesh files
  std::vector<std::string> layouts{"single", "pssm", "tsm", "pssm+tsm"};
  std::vector<int> cascade_counts{4};                     // for pssm and pssm+tsm
  int total_size = 4096;                                  // side of the single map; the others match its texels
  bool unstabilized_too = true;                           // pssm also without stabilisation (the flicker figure)
  std::vector<std::string> methods{"pcf", "esm", "vsm"};  // check_layout_method's names
  int blur_radius = 1;                                    // in layer 0's texels (layered.hpp scales it per layer)
  Lookup lookup = Lookup::Mips;
  int frames = 4;                    // along the camera path
  std::string camera_path = "walk";  // walk | orbit (layer_render.hpp)
  // Camera motion per frame: a walk's step (scene units: metres in city and treeline) along the
  // look direction on the ground, an orbit's angle (degrees). 0.05 m is a walk, 1.5 m/s at 30
  // frames per second: half a texel of a 2048 cascade over city's first 100 m, so a texel grid
  // that follows the camera crawls every frame, and few receivers change layers.
  double walk_step = 0.05, orbit_step_degrees = 0.05;
  // A moving light: its direction turns this many degrees per frame about the world's up axis (y),
  // keeping its elevation, as a sun over a day; the camera follows its path as without it (a step
  // of 0 keeps it still). 0: the light stays.
  double light_step_degrees = 0.0;
  int receivers_width = 1920, receivers_height = 1080;
  int soft_samples = 16;  // 0: no soft reference (its RMSE column is empty)
  double split_lambda = LayoutOptions{}.split_lambda;
  double tsm_focus = LayoutOptions{}.tsm_focus;
  double blend = 0.1;
  int timing_runs = 3;  // per frame and configuration (median)
  int threads = 0;
  std::string device;
};

// The figures of one (scene, layout, method), averaged over the frames (flicker over frame pairs).
struct LayoutRow {
  std::string scene, layout, method;
  int layers = 1, layer_size = 0;
  bool stabilize = true;
  int frames = 0;
  size_t counted = 0;                    // receivers compared per frame (mean)
  double rmse_hard = 0, rmse_soft = -1;  // -1: no soft reference
  double mismatch = 0;                   // fraction with (v >= 0.5) != (hard reference lit)
  double mismatch_near = 0;              // the same over the nearest 10% of the camera's view depths
  size_t counted_near = 0;
  // Shadow-map texels per screen pixel along a pixel's side (the footprint f of its layer), over
  // the frame's receivers and over the nearest 10%: quantiles; < 1 is a texel larger than a pixel
  // (perspective aliasing).
  double texels_p10 = 0, texels_p50 = 0, texels_p90 = 0, texels_near_p50 = 0;
  // Flicker: mean |e_t - e_{t-1}| over frame pairs at the same world points, e = v - reference (the
  // soft reference for the soft methods when there is one, else the hard one); -1: one frame.
  // Under a still light the reference at a world point does not change, so it is |v_t - v_{t-1}|.
  double flicker = -1;
  double time_ms = 0;  // per frame: layers' transform, blur, pyramids, reconstruction, blend
  double prefilter_ms = 0, reconstruct_ms = 0;
};

// Metrics of one frame (exposed for the tests).
struct FrameMetrics {
  size_t counted = 0, counted_near = 0;
  double sq_hard = 0, sq_soft = 0, mismatched = 0, mismatched_near = 0;
};
// Accumulates one frame: v against the references over `mask`; near marks the nearest 10%.
FrameMetrics frame_metrics(const std::vector<float>& v, const std::vector<float>& ref_hard,
                           const std::vector<float>& ref_soft, const std::vector<uint8_t>& mask,
                           const std::vector<uint8_t>& near);
// Mean |a - b| over mask (0 when the mask is empty).
double mean_abs_difference(const std::vector<float>& a, const std::vector<float>& b, const std::vector<uint8_t>& mask);
// Quantile q in [0, 1] of the values (nearest rank; 0 for none).
double quantile(std::vector<double> values, double q);

// A name of --methods: a method of FilterOptions (methods.hpp) or a soft method (soft.hpp: pcss,
// cssm, ssmm, ssmm-improved, under the scene's area light on every layer, layered.hpp);
// InputError naming both kinds otherwise.
void check_layout_method(const std::string& name);

// Runs the whole comparison; `progress` (may be empty) gets one line per finished step.
std::vector<LayoutRow> evaluate_layouts(const std::shared_ptr<Runtime>& rt, const LayoutEvalRequest& request,
                                        const std::function<void(const std::string&)>& progress = {});

// results_layouts.csv; a Markdown table in the shape of Oliveira 2009's Table 2 with the error columns.
void write_layout_csv(const std::string& path, const std::vector<LayoutRow>& rows);
std::string layout_markdown(const std::vector<LayoutRow>& rows);
// layouts_<scene>.png: per layout, the methods' mismatched pixels in the nearest 10% and their
// flicker, as bars (8-bit RGB, written atomically).
void write_layout_plot(const std::string& path, const std::vector<LayoutRow>& rows, const std::string& scene);

}  // namespace sf::eval

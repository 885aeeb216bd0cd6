#pragma once
// `shadowfilter evaluate` and `--auto`: run methods over a parameter grid on a scene,
// time them honestly (median of repeated device-resident runs after warm-up) and measure their
// error against the exact filtered test s_ref with the same weights and against the ray-traced
// references. Library-level: the CLI only parses options and prints. This module reads and
// writes files (scenes, CSV/JSON, PNG); the OpenCL library stays free of file I/O.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/runtime.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::eval {

// A scene directory of the generator (docs/scenes.md): shadowmap.exr, receivers.exr and the
// ray-traced camera-view references (optional).
struct Scene {
  std::string name, dir;
  HostImage depth;
  Receivers receivers;
  HostImage ref_hard, ref_soft;  // empty (0x0) when the file is missing
  // Receivers that the map can shadow: finite d, (u, v) inside [0,1]^2. Errors count only these.
  std::vector<uint8_t> valid;
  size_t valid_count = 0;
  // The receivers of every figure against the ray-traced references: valid and not facing away
  // from the light (ndl > 0; all valid ones when the receivers carry no ndl, and where ndl is
  // unknown). A renderer's n.l term darkens a facing-away surface whatever its shadow says, so
  // counting it (the hard reference has 0 there) would score a method on pixels nobody sees lit.
  std::vector<uint8_t> traced;
  size_t traced_count = 0;
  double max_footprint = 1.0;  // over valid receivers (1 when the receivers carry none)
  // The area light of the map's header as `scene` writes it (light_type, near, far,
  // ortho_extents or fov_degrees, light_size and light_height): what the soft methods run
  // under. None when the header names no light_size or an attribute it needs is missing or not
  // a finite number; `no_light` then says which (the soft methods are skipped with it, the
  // others run).
  std::optional<SoftLight> light;
  std::string no_light;
};
Scene load_scene(const std::string& dir);
// A scene from memory (filter --auto): no ray-traced references.
Scene make_scene(std::string name, HostImage depth, Receivers receivers);
// A soft visibility image of a user's own (soft --auto --reference): one channel, read as every
// input image is; InputError otherwise. Its values are checked where they are compared
// (choose_soft_auto).
HostImage load_soft_reference(const std::string& path);

// s_ref in evaluations tests each texel against the receiver's plane (FilterOptions::
// receiver_plane, docs/receiver_plane.md), sum_t W_x(t) H(z_t - d_t + b): exact for planar
// receivers, so tilted lit floors are lit in it as in the ray-traced reference. b is the same tie
// bias sm and pcf default to (2^-15: the inputs' rounding); sm and pcf run with the same bias and
// plane, so they compute s_ref itself. --sref-bias sets another b.
constexpr double kDefaultSrefBias = 1.0 / 32768.0;

// --- the parameter grid -----------------------------------------------------------------------
enum class Grid { Quick, Default, Wide };
Grid parse_grid(const std::string& name);  // quick | default | wide; InputError otherwise
// "all" or a comma-separated list of method names (validated against the registry).
std::vector<std::string> parse_methods(const std::string& list);
// evaluate's --methods: the registry's methods as parse_methods takes them, and the soft methods
// (soft.hpp: pcss, cssm, ssmm, ssmm-improved; "soft" names all four; "all" names the registry's
// only), each list in the order given. InputError names both kinds for an unknown name.
struct MethodLists {
  std::vector<std::string> hard;
  std::vector<SoftMethod> soft;
};
MethodLists parse_evaluated_methods(const std::string& list);
// Every configuration of the grid for these methods. Footprint lookups (mips, sat) are only
// generated when `max_footprint` > 1 (otherwise they equal bilinear and only cost time).
// sm and pcf get depth_test.bias = sref_bias (so that they compute s_ref itself). Where the
// receivers carry Jacobians (`jacobian`), the default and wide grids add each footprint lookup's
// isotropic twin (max_anisotropy 1, labelled "iso") beside the anisotropic default.
std::vector<FilterOptions> make_grid(const std::vector<std::string>& methods, Grid grid, double max_footprint,
                                     double sref_bias = kDefaultSrefBias, bool jacobian = false);
// One short human-readable label: "esm c=80 R=3 mips f32" ("mips iso", "mips aniso4" where
// max_anisotropy is not the default 8).
std::string config_label(const FilterOptions& o);
// The soft methods' grid (their parameters; the light is the scene's): pcss; cssm M = 4 with mips
// and with the SAT (default: also M = 8 and 16 with mips; wide: and with the SAT); ssmm n = 4
// (default: 3, 4, 6); ssmm-improved n = 4 (default: 3, 4). Labels: "cssm M=4 mips", "ssmm n=4".
// Each grid entry is `base` (the light and the knobs the grid does not vary: bias, receiver plane,
// max width, ...) with the method and the varied parameters set.
std::vector<SoftOptions> make_soft_grid(const std::vector<SoftMethod>& methods, Grid grid,
                                        const SoftOptions& base = {});
std::string soft_label(const SoftOptions& o);

// --- errors -----------------------------------------------------------------------------------
struct ErrorStats {
  size_t n = 0;  // receivers compared
  double rmse = 0, p99 = 0, max = 0;
  double frac_1_255 = 0, frac_005 = 0;  // |v - ref| > 1/255, > 0.05
  double leak = 0, darken = 0;          // v > ref + 0.05, v < ref - 0.05
  bool valid = false;
};
ErrorStats error_stats(const std::vector<float>& v, const std::vector<double>& ref, const std::vector<uint8_t>& mask);
// Acne and leaks against the hard reference, over the receivers of `mask`, on the
// receiver image's grid: a receiver is "lit inside" when the hard reference is lit (>= 0.5) at
// every counted receiver of the (2 radius + 1)^2 window around it, and "shadowed inside" when it
// is shadowed at every one (the window clipped to the image). Receivers outside `mask` (misses,
// outside the frustum, facing away) are not in any window: they say nothing about the light there,
// so a lit receiver next to the background or a terminator still counts as lit inside. The window
// keeps the penumbra band of a filter off both counts: what is left is acne (lit inside, output
// < 0.5) and leaks (shadowed inside, output > 0.5), as fractions of their class.
constexpr int kAcneLeakRadius = 3;  // 7x7
struct AcneLeak {
  size_t lit = 0, shadowed = 0;  // receivers lit inside / shadowed inside
  double acne = 0, leak = 0;     // fraction of `lit` below 0.5 / of `shadowed` above 0.5 (0 when none)
  bool valid = false;            // the reference matched the size of v
};
AcneLeak acne_leak(const std::vector<float>& v, const HostImage& ref_hard, const std::vector<uint8_t>& mask,
                   int radius = kAcneLeakRadius);

// Metric by name: rmse, p99, max, frac_1_255, frac_005, leak, darken. InputError otherwise.
double metric_value(const ErrorStats& e, const std::string& metric);
void check_metric(const std::string& metric);

// s_ref of a scene for the weights of (blur, lookup, max_anisotropy where the receivers carry
// Jacobians; footprint.hpp), computed once per key on all cores.
class SrefCache {
 public:
  explicit SrefCache(const Scene& scene, double bias = kDefaultSrefBias) : scene_(scene), bias_(bias) {}
  double bias() const { return bias_; }
  // The weights a configuration's output approximates: sm has no prefilter, sm and pcf read the
  // raw depth through bilinear weights (pipeline.cpp), everything else (blur, lookup).
  const std::vector<double>& for_options(const FilterOptions& o);
  const std::vector<double>& get(const BlurOptions& blur, Lookup lookup,
                                 int max_anisotropy = LookupOptions{}.max_anisotropy);

 private:
  const Scene& scene_;
  double bias_;
  std::map<std::string, std::vector<double>> cache_;
};
// Against each receiver's plane (ref::receiver_plane under `plane`; off: the constant d).
std::vector<double> s_ref_parallel(const HostImage& depth, const BlurOptions& blur, Lookup lookup, const Receivers& rx,
                                   double bias = 0.0, const ReceiverPlaneOptions& plane = {},
                                   int max_anisotropy = LookupOptions{}.max_anisotropy);

// --- timing -----------------------------------------------------------------------------------
struct Measured {
  std::vector<float> visibility;  // receivers.count()
  double median_ms = 0;           // wall: prefilter + reconstruct + finish, data on the device
  double min_ms = 0;
  StageTimes stages;  // median per stage (device profiling)
  size_t device_bytes = 0;
  int runs = 0;
};
struct TimingSettings {
  int warmup = 1;
  int runs = 5;
};
// Throws InputError when the options are refused (e.g. a storage the method cannot hold).
Measured measure(const std::shared_ptr<Runtime>& rt, const FilterOptions& o, const Scene& scene,
                 const TimingSettings& t);
// A soft method under the scene's light (InputError without one, or for options validate()
// refuses), timed the same way; planar receivers (Receivers::grid) are read at their texel centres.
Measured measure(const std::shared_ptr<Runtime>& rt, const SoftOptions& o, const Scene& scene, const TimingSettings& t);

// --- one evaluated configuration ----------------------------------------------------------------
struct Row {
  std::string scene, method, label;
  FilterOptions options;
  double time_ms = 0, min_ms = 0;
  StageTimes stages;
  size_t device_bytes = 0;
  int runs = 0;
  // sref: against s_ref of the configuration's own weights (the "self" reference, a fidelity
  // figure); target: against s_ref of the run's target filter (both over Scene::valid); hard,
  // soft: against the ray-traced references over Scene::traced.
  ErrorStats sref, hard, soft, target;
  AcneLeak acne_leak;             // against reference_hard over Scene::traced
  std::vector<float> visibility;  // kept for error images; cleared when not needed
  // A soft method's row: its options (`options` is then unused). It has no s_ref (its filter is
  // the light's, not a footprint of the map): sref and target stay invalid.
  std::optional<SoftOptions> soft_options;
};
// `target_ref` (may be null: Row::target stays invalid) is s_ref of the target filter.
Row evaluate_config(const std::shared_ptr<Runtime>& rt, const Scene& scene, const FilterOptions& o, SrefCache& sref,
                    const TimingSettings& t, const std::vector<double>* target_ref = nullptr);
// A row's identity and timings from one measurement; the caller adds the errors it needs.
Row timed_row(const Scene& scene, const FilterOptions& o, const Measured& m);
Row timed_row(const Scene& scene, const std::string& method, const std::string& label, const Measured& m);
// A soft method under the scene's light (InputError without one, or for options validate()
// refuses), timed as measure() times a pipeline (prefilter + reconstruct + finish), its errors
// against the ray-traced references and its acne and leaks.
Row evaluate_soft_config(const std::shared_ptr<Runtime>& rt, const Scene& scene, const SoftOptions& o,
                         const TimingSettings& t);

struct Skipped {
  std::string scene, label, reason;
};

// --- references and the Pareto front (pareto.cpp) ---------------------------------------------
// What an error is measured against. A plot or a ranking needs one reference for every
// configuration: the ray-traced shadows (what the scene looks like) or s_ref of one target filter
// (what a renderer asked for). Self, s_ref with each configuration's own weights, differs per
// configuration: sm and pcf compute it exactly and score 0 by definition, so it measures how well
// a method approximates its own filtered test (fidelity), not which output looks closest.
enum class Reference { Soft, Hard, Target, Self };
Reference parse_reference(const std::string& name);  // soft | hard | target | self; InputError otherwise
const char* reference_name(Reference r);             // the names above, also the CSV column prefixes
// The filter a renderer wants: s_ref of these weights is the "target" reference.
struct TargetFilter {
  BlurOptions blur{3, 0.0f};
  Lookup lookup = Lookup::Mips;
};
std::string target_text(const TargetFilter& t);  // "R=3 mips"
// What the errors against `r` compare with, for titles and axes: "ray-traced soft shadow
// (reference_soft.exr)", "s_ref of the target filter R=3 mips", ...
std::string reference_text(Reference r, const TargetFilter& t);
// Whether the scene holds the reference (soft, hard: the ray-traced image; target, self: always).
bool has_reference(const Scene& s, Reference r);
// The reference a scene's plot uses: `requested`, or the target s_ref when the scene lacks the
// ray-traced image asked for; `note` (may be null) then says so in one line, else is cleared.
Reference plot_reference(const Scene& s, Reference requested, std::string* note);
// "rmse" -> "RMSE", "p99" -> "p99 |error|", ...; check_metric's names.
std::string metric_text(const std::string& metric);
// A metric name with an optional reference prefix ("hard_rmse", "self_p99"; "sref_" is self):
// the bare metric, and the prefix's reference in `ref` when there is one (returns false without).
bool split_metric(const std::string& name, std::string* metric, Reference* ref);

const ErrorStats& row_errors(const Row& r, Reference ref);
double row_error(const Row& r, Reference ref, const std::string& metric);
// Prefixed name as split_metric reads it; a bare metric is against self (s_ref, own weights).
double row_metric(const Row& r, const std::string& metric);

// The non-dominated points of (time, error), fastest first (equal times: lower error first):
// i is on the front unless some j has time_j <= time_i and error_j <= error_i with one of them
// strictly smaller. Equal points are both on it. Points with a non-finite time or error are on
// no front (a NaN compares with nothing).
std::vector<size_t> pareto_front(const std::vector<double>& time, const std::vector<double>& error);
std::vector<size_t> pareto_front(const std::vector<Row>& rows, Reference ref, const std::string& metric);
std::vector<size_t> pareto_front(const std::vector<Row>& rows, const std::string& metric);  // row_metric's names

// The text of a Pareto plot; every line names the reference. Stored in the PNG as
// "ImageDescription" (description()), so that a reader of the file finds what it shows.
struct PlotLabels {
  std::string title;     // "spheres: time vs RMSE against ray-traced soft shadow (reference_soft.exr)"
  std::string subtitle;  // configurations, receivers counted, a fallback note
  std::string x_axis, y_axis;
  std::string description() const;  // the four lines, newline-separated
};
PlotLabels pareto_labels(const Scene& scene, size_t configurations, Reference ref, const std::string& metric,
                         const TargetFilter& target, const std::string& note = "");

// --- outputs ----------------------------------------------------------------------------------
void write_csv(const std::string& path, const std::vector<Row>& rows, const TargetFilter& target = {});
void write_json(const std::string& path, const std::vector<Row>& rows, const std::vector<Skipped>& skipped,
                const std::string& device, const TargetFilter& target = {});
// Time vs error against one reference, one point per configuration, methods coloured, the
// Pareto front drawn; log-scaled time axis. 8-bit RGB PNG, written atomically, `labels` in its
// text and in its "ImageDescription".
void write_pareto_png(const std::string& path, const std::vector<Row>& rows, Reference ref, const std::string& metric,
                      const PlotLabels& labels);
// |v - s_ref| of one configuration as a heat image (black 0, white >= `full_scale`), PNG.
void write_error_png(const std::string& path, const Scene& scene, const std::vector<float>& v,
                     const std::vector<double>& ref, double full_scale);

// --- contact sheets (contact_sheet.cpp) -----------------------------------------------------------
// One picture per scene: the reference, then each method's best configuration, each with its
// signed error map (output - reference) beneath, on a diverging scale (blue: darker than the
// reference, white: equal, red: brighter; saturated at +-kContactErrorScale) with a legend bar.
constexpr double kContactErrorScale = 0.25;
// Where the cells of a sheet lie: `tiles` cells (the reference and one per method), at most
// `columns` per row, each image reduced by `shrink` (an integer, so that no cell is wider than
// kContactTileWidth) and shown as tile_w x tile_h.
constexpr int kContactTileWidth = 320;
struct ContactLayout {
  int shrink = 1, tile_w = 0, tile_h = 0, columns = 0, rows = 0;
  int cell_w = 0, cell_h = 0;  // a label band, the picture, the error map beneath
  int width = 0, height = 0;   // the sheet, title band included
  int cell_x(size_t k) const;  // left edge of cell k
  int cell_y(size_t k) const;  // top edge of cell k (its label band)
};
ContactLayout contact_layout(int receivers_w, int receivers_h, size_t tiles);
// The sheet's reference image (soft, hard: the ray-traced picture; target: its s_ref) and the
// receivers it counts; self has no single picture, so a sheet asked for self shows the soft
// reference (the target where there is none).
Reference contact_reference(const Scene& s, Reference plot_ref);
// Per method, the configuration of lowest `metric` against `ref` (faster on ties), in the order
// the methods first appear in `rows`; rows without the reference are skipped.
std::vector<size_t> best_per_method(const std::vector<Row>& rows, Reference ref, const std::string& metric);
// Writes the sheet of `best` (indices into rows, their visibility kept) against `ref` for the
// scene; `target_ref` is the target's s_ref (needed when ref is Target). 8-bit RGB PNG, atomic.
void write_contact_sheet(const std::string& path, const Scene& scene, const std::vector<Row>& rows,
                         const std::vector<size_t>& best, Reference ref, const std::string& metric,
                         const TargetFilter& target, const std::vector<double>& target_ref);

// --- --auto -----------------------------------------------------------------------------------
// The search: every candidate (method x parameters x lookup x storage, esm also x classification)
// is ordered by an estimated cost, measured in that order, and the search stops at the first one
// whose error against s_ref of the target weights is <= max_error; candidates whose estimate is
// within `cost_slack` of that first hit are measured too (the estimate is rough). The choice is
// by measured time, made robust to a loaded machine: the candidates that meet the bound (those
// whose first run is within 3x of the fastest, at most 8) run again in `final_rounds`
// interleaved rounds; each scores the median over the rounds of its time over the round's
// fastest, and among those within the tie band of the best score (the noise of the rounds, at
// least `time_tolerance`) the one with the lowest estimate is chosen: a tie within noise goes to
// the cheaper configuration, the same one on every run. What the scene
// does not need is never generated: no mips / sat when every footprint <= 1 (they equal
// bilinear), no z-max pyramid unless a candidate classifies; a larger csm order or a wider
// storage only comes after the cheaper ones.
struct AutoRequest {
  double max_error = 0.05;
  std::string metric = "p99";  // against s_ref of the target weights
  double sref_bias = kDefaultSrefBias;
  FilterOptions target;  // its blur and lookup define the target weights
  // true: the target lookup is what the scene needs (trilinear mips when some footprint > 1,
  // bilinear otherwise) instead of target.lookup.
  bool lookup_from_scene = false;
  std::vector<std::string> methods;  // empty = every method
  TimingSettings timing;
  double cost_slack = 1.5;
  int final_rounds = 5;          // interleaved re-measurements of the finalists (0: the first pass only)
  double time_tolerance = 0.05;  // least tie band: minimum times within it of the fastest are a tie
};
struct AutoCandidate {
  FilterOptions options;
  double cost = 0;  // estimated ms on the development machine (ordering only)
};
// Estimated milliseconds of prefilter + reconstruct on a w x h map and n receivers: per-texel and
// per-receiver costs by method, channels, storage bytes and lookup, taken from the quick grid on
// the 2-core development machine (docs/results.md). Only its order matters.
double estimated_cost(const FilterOptions& o, int map_w, int map_h, size_t receivers);
struct AutoResult {
  bool found = false;
  FilterOptions chosen;
  Row chosen_row;
  FilterOptions target;              // after the scene's needs (mips dropped when f <= 1)
  std::string first_hit;             // label of the first candidate under the bound (cost order)
  std::vector<std::string> skipped;  // "what: why"
  std::vector<std::string> notes;    // what the scene needs
  std::vector<Row> tried;            // measured, in cost order; min_ms over every run (final rounds too)
  struct Finalist {
    std::string label;
    double min_ms = 0;  // fastest run
    double score = 0;   // median over the final rounds of its time / the round's fastest
    double cost = 0;    // estimate
  };
  std::vector<Finalist> finalists;  // the re-measured candidates under the bound, best score first
  double chosen_score = 0;
  std::string tie;                       // when the choice is not the fastest run: why (the tie rule)
  double noise = 0;                      // measured: median over the finalists of median / min - 1 of their ratios
  double tolerance = 0;                  // the tie band used: max(time_tolerance, noise)
  std::vector<double> tried_cost;        // their estimates
  std::vector<AutoCandidate> not_tried;  // costlier than cost_slack x the first hit
  std::vector<Skipped> refused;
};
// Every candidate for the target on this scene, cheapest estimate first; `refused` gets those the
// methods reject (e.g. esm c = 80 in f16).
std::vector<AutoCandidate> auto_candidates(const Scene& scene, const AutoRequest& req, const FilterOptions& target,
                                           std::vector<Skipped>* refused);
// The decision among choose_auto's finalists from their measured times alone: rounds[r][k] is
// finalist k's time in round r (the first pass when there were no rounds), cost[k] its estimate.
// score[k] = median over the rounds of its time / the round's fastest; the tie band is
// max(time_tolerance, noise), noise = median over the finalists of score / least ratio - 1;
// the lowest estimate within the band of the best score wins (earlier in `order` on equal cost).
struct TimedChoice {
  std::vector<double> score;
  std::vector<size_t> order;  // finalists by score, best first (stable)
  double noise = 0;           // 0 for one finalist
  double tolerance = 0;
  size_t pick = 0;  // the chosen finalist
};
// Throws InputError without rounds or finalists, or when a round's size is not cost.size().
TimedChoice choose_by_times(const std::vector<std::vector<double>>& rounds, const std::vector<double>& cost,
                            double time_tolerance);
// `progress` (may be empty) is called after each candidate with (done, total).
AutoResult choose_auto(const std::shared_ptr<Runtime>& rt, const Scene& scene, const AutoRequest& req,
                       const std::function<void(size_t, size_t)>& progress = {});
std::string describe(const AutoResult& r, const std::string& metric = "p99");  // the lines --auto prints

// `soft --auto`: the fastest soft configuration whose error against the scene's soft reference
// (Scene::ref_soft: a ray-traced, or otherwise exact, soft visibility of the same receivers, over
// Scene::traced) stays under the bound. A soft method filters with the light's footprint, not a
// footprint of the map, so there is no s_ref to aim at and no cost model: every configuration of
// the grid (make_soft_grid over `methods` from `base`, the scene's light) is measured, and the
// ones under the bound are compared as choose_auto compares its finalists, a tie within noise
// going to the one with fewer device bytes. The result's rows are soft rows (Row::soft_options;
// chosen_row.soft_options is the choice, `chosen` is unused; their error is Row::soft).
// InputError when the scene has no light or no soft reference of the receivers' size, or when
// the reference holds a counted value that is not a finite number in [0, 1].
struct SoftAutoRequest {
  double max_error = 0.05;
  std::string metric = "rmse";      // against the soft reference
  std::vector<SoftMethod> methods;  // empty = all four
  Grid grid = Grid::Default;
  SoftOptions base;
  TimingSettings timing{1, 3};
  int final_rounds = 5;
  double time_tolerance = 0.05;
  std::string reference = "the soft reference";  // what the notes call it (a file name)
};
AutoResult choose_soft_auto(const std::shared_ptr<Runtime>& rt, const Scene& scene, const SoftAutoRequest& req,
                            const std::function<void(size_t, size_t)>& progress = {});
// The errors a row of --auto is judged by: a soft row's against the soft reference, any other's
// against s_ref.
const ErrorStats& auto_errors(const Row& row);

}  // namespace sf::eval

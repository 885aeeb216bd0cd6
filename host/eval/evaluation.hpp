#pragma once
// `shadowfilter evaluate` as a library call: every configuration of a grid on scene directories,
// timed and compared with the references, then results.csv / results.json, per scene the Pareto
// plots (pareto_<scene>.png against the plot's reference, pareto_<scene>_<reference>.png against
// each other one), the contact sheet contact_<scene>.png, one error image per method and, with
// an --auto request, auto.txt. Every file goes through host/io's writer (output_file.hpp).
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "evaluate.hpp"
#include "flicker.hpp"

namespace sf::eval {

struct EvaluationRequest {
  std::vector<std::string> dirs;  // scene directories (load_scene)
  std::string out_dir;            // created when missing
  std::vector<std::string> methods;
  std::vector<SoftMethod> soft_methods;  // run under each scene's light (Scene::light)
  Grid grid;
  Reference reference = Reference::Soft;  // of the plots (plot_reference may fall back to target)
  std::string metric = "rmse";            // of the plots and contact sheets
  TargetFilter target;
  TimingSettings timing;
  double sref_bias = kDefaultSrefBias;
  bool images = true;     // the PNGs
  bool progress = false;  // a progress bar per scene on std::cerr
  // With a value: per scene the fastest configuration under its bound (choose_auto), written to
  // auto.txt, and make_grid only what each scene needs. Its methods and timing are the request's.
  std::optional<AutoRequest> auto_request;
  // The directories are consecutive frames from one still camera (flicker.hpp): per
  // configuration its flicker over the sequence, in results_frames.csv, results_frames.md and
  // (with images) flicker.png. InputError for fewer than two, or frames that are not one
  // sequence (FlickerTracker::add_frame), before any configuration runs.
  bool frames = false;
  // How a refused configuration's reason reads (the CLI names its own flags: cli_message).
  std::function<std::string(const std::string&)> describe_refusal = [](const std::string& m) { return m; };
};

struct EvaluationResult {
  std::vector<Row> rows;  // without their visibility images
  std::vector<Skipped> skipped;
  std::vector<std::string> auto_lines;  // per scene "== NAME\n" and describe()
  size_t scenes = 0;
  std::string device_name;
  std::vector<FlickerRow> flicker;  // with frames: per configuration over the sequence
  std::string flicker_reference;    // "soft" or "hard"
};

// Runs the request on `runtime` and writes its files; one line per scene whose plot falls back to
// another reference goes to `notes`. InputError for a scene that cannot be read or an output
// directory that cannot be made.
EvaluationResult run_evaluation(const EvaluationRequest& request, const std::shared_ptr<Runtime>& runtime,
                                std::ostream& notes);

// The summary table: per row the time, the RMSE against each reference (-1 where the scene has
// none), acne and leak percentages and device memory, then the skipped configurations.
std::string summary_table(const EvaluationResult& result);

}  // namespace sf::eval

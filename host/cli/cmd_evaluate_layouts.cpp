// `shadowfilter evaluate-layouts SCENE... -o OUT`: shadow-map layouts x cascade counts x methods
// at equal total texels along a camera path, against the ray-traced references of every frame
// (host/eval/layout_eval.hpp, docs/cascades.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "output_file.hpp"
#include "layout_eval.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "verbose.hpp"

namespace sf::cli {
namespace {

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ','))
    if (!item.empty()) items.push_back(item);
  return items;
}

}  // namespace

CLI::App* add_evaluate_layouts_command(CLI::App& app, EvaluateLayoutsArgs& a) {
  CLI::App* c = app.add_subcommand(
      "evaluate-layouts",
      "Compare shadow-map layouts (single, pssm, tsm, pssm+tsm) x cascade counts x methods at equal total "
      "texels along a camera path: errors against ray-traced references (all receivers and the nearest 10% "
      "of the view), texels per pixel, flicker between frames and time per frame");
  c->add_option("scenes", a.scenes, "Built-in scene names (city, treeline, ...) or mesh files")->required();
  c->add_option("-o,--output", a.out_dir,
                "Output directory (results_layouts.csv, results_layouts.md, layouts_SCENE.png)")
      ->required();
  c->add_option("--layouts", a.layouts, "Comma-separated: single, pssm, tsm, pssm+tsm")->capture_default_str();
  c->add_option("--cascade-counts", a.cascade_counts, "Comma-separated layer counts of pssm and pssm+tsm")
      ->capture_default_str();
  c->add_option("--total-size", a.request.total_size,
                "Side of the single map; every layout gets its texels (K layers of total/sqrt(K))")
      ->capture_default_str();
  c->add_flag("!--no-unstable", a.request.unstabilized_too, "Leave out pssm without stabilisation");
  c->add_option("--methods", a.methods,
                "Comma-separated methods: filter's, and the soft ones (pcss, cssm, ssmm, ssmm-improved) on layouts "
                "without a warp (single, pssm)")
      ->capture_default_str();
  c->add_option("--blur-radius", a.request.blur_radius, "Gaussian radius in layer 0's texels (scaled per layer)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_option("--lookup", a.lookup, "bilinear | mips | sat")
      ->capture_default_str()
      ->check(CLI::IsMember({"bilinear", "mips", "sat"}));
  c->add_option("--frames", a.request.frames, "Frames along the camera path (or the light's, --light-step)")
      ->capture_default_str();
  c->add_option("--camera-path", a.request.camera_path, "walk | orbit")
      ->capture_default_str()
      ->check(CLI::IsMember({"walk", "orbit"}));
  c->add_option("--step", a.request.walk_step, "Walk: metres (scene units) per frame")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  c->add_option("--orbit-step", a.request.orbit_step_degrees, "Orbit: degrees per frame")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 360.0));
  c->add_option("--light-step", a.request.light_step_degrees,
                "A moving light: degrees its direction turns per frame about the up axis (a sun over a day); "
                "with --step 0 the camera stands still")
      ->capture_default_str()
      ->check(CLI::Range(-360.0, 360.0));
  c->add_option("--receivers", a.receivers, "Camera view WIDTHxHEIGHT")->capture_default_str();
  c->add_option("--samples", a.request.soft_samples, "Area-light samples of the soft reference (a square; 0 = none)")
      ->capture_default_str();
  c->add_option("--split-lambda", a.request.split_lambda, "Practical split blend (0 uniform .. 1 logarithmic)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--tsm-focus", a.request.tsm_focus,
                "Trapezoids' focus point, a fraction of each slice's log depth range (80% rule)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--cascade-blend", a.request.blend, "Blend band, a fraction of each layer's range")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.99));
  c->add_option("--runs", a.request.timing_runs, "Timed runs per frame and configuration (median)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  c->add_option("--threads", a.request.threads, "Ray-casting threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_option("--device", a.request.device, "OpenCL device (as for filter)");
  c->add_flag("-q,--quiet", a.quiet, "No progress lines");
  add_verbose_flag(*c, a.verbose);
  return c;
}

int run_evaluate_layouts(EvaluateLayoutsArgs& a) {
  namespace fs = std::filesystem;
  eval::LayoutEvalRequest& r = a.request;
  r.scenes = a.scenes;
  r.layouts = split_list(a.layouts);
  r.methods = split_list(a.methods);
  r.cascade_counts.clear();
  for (const std::string& k : split_list(a.cascade_counts)) {
    int count = 0;
    if (std::sscanf(k.c_str(), "%d", &count) != 1 || count < 1 || count > kMaxCascadeLayers)
      throw InputError("--cascade-counts: '" + k + "' is not a layer count in 1.." + std::to_string(kMaxCascadeLayers));
    r.cascade_counts.push_back(count);
  }
  if (r.layouts.empty()) throw InputError("--layouts names no layout");
  for (const std::string& l : r.layouts) parse_layout(l);
  if (std::sscanf(a.receivers.c_str(), "%dx%d", &r.receivers_width, &r.receivers_height) != 2 ||
      r.receivers_width < 1 || r.receivers_height < 1 || r.receivers_width > 16384 || r.receivers_height > 16384)
    throw InputError("--receivers must be WIDTHxHEIGHT (1..16384), not '" + a.receivers + "'");
  const int root = static_cast<int>(std::lround(std::sqrt(std::max(0, r.soft_samples))));
  if (r.soft_samples < 0 || root * root != r.soft_samples) throw InputError("--samples must be a square number");
  r.lookup = a.lookup == "bilinear" ? Lookup::Bilinear : a.lookup == "sat" ? Lookup::Sat : Lookup::Mips;
  for (const std::string& m : r.methods) eval::check_layout_method(m);
  if (r.methods.empty()) throw InputError("--methods names no method");

  auto runtime = Runtime::create(r.device);
  apply_verbose(*runtime, a.verbose);
  const auto rows = eval::evaluate_layouts(runtime, r, [&](const std::string& line) {
    if (!a.quiet) std::cerr << line << "\n";
  });
  // The output directory only once there is something to write: bad input leaves nothing.
  std::error_code ec;
  fs::create_directories(a.out_dir, ec);
  if (!fs::is_directory(a.out_dir)) throw InputError("cannot create output directory '" + a.out_dir + "'");
  const std::string table = eval::layout_markdown(rows);
  eval::write_layout_csv((fs::path(a.out_dir) / "results_layouts.csv").string(), rows);
  io::write_text((fs::path(a.out_dir) / "results_layouts.md").string(), "results file", table);
  std::vector<std::string> scenes;
  for (const auto& row : rows)
    if (std::find(scenes.begin(), scenes.end(), row.scene) == scenes.end()) scenes.push_back(row.scene);
  for (const std::string& scene : scenes)
    eval::write_layout_plot((fs::path(a.out_dir) / ("layouts_" + scene + ".png")).string(), rows, scene);
  if (!a.quiet) std::cout << table;
  return 0;
}

}  // namespace sf::cli

// `shadowfilter evaluate DIR... -o OUT`: every method over a parameter grid on scene directories;
// results.csv / results.json, pareto_<scene>.png and one error image per method (host/eval).
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include "commands.hpp"
#include "option_names.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"
#include "verbose.hpp"

namespace sf::cli {

CLI::App* add_evaluate_command(CLI::App& app, EvaluateArgs& a) {
  CLI::App* c = app.add_subcommand("evaluate",
                                   "Run methods over a parameter grid on scene directories: time, memory and errors "
                                   "against s_ref and the ray-traced references; CSV, JSON and Pareto plots");
  c->add_option("dirs", a.dirs, "Scene directories (shadowmap.exr, receivers.exr, reference_*.exr)")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("-o,--output", a.out_dir, "Output directory")->required();
  c->add_option("--methods", a.methods, "'all' or a comma-separated list of methods")->capture_default_str();
  c->add_option("--grid", a.grid, "Parameter grid: quick | default | wide")->capture_default_str();
  c->add_option("--runs", a.runs, "Timed runs per configuration (median), after --warmup")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  c->add_option("--warmup", a.warmup, "Untimed runs first")->capture_default_str()->check(CLI::Range(0, 100));
  c->add_option("--pareto-metric", a.pareto_metric,
                "Error axis of the plots: METRIC against s_ref, or hard_METRIC / soft_METRIC")
      ->capture_default_str();
  c->add_option("--device", a.device, "OpenCL device (as for filter)");
  c->add_flag("--no-images", a.no_images, "Write no PNGs");
  c->add_flag("-q,--quiet", a.quiet, "No progress bar and no summary table");
  add_verbose_flag(*c, a.verbose);
  c->add_flag("--auto", a.auto_args.enabled,
              "Only what each scene requires (no mips / sat when every footprint <= 1), then search "
              "methods, parameters, lookups and storages in estimated-cost order for the fastest "
              "configuration under --max-error against s_ref of the --auto-radius / --auto-lookup weights");
  c->add_option("--auto-radius", a.auto_radius, "--auto: Gaussian radius of the target weights")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_option("--auto-lookup", a.auto_lookup,
                "--auto: lookup of the target weights: auto (trilinear mips where some footprint > 1, "
                "else bilinear) | bilinear | mips | sat")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "bilinear", "mips", "sat"}));
  c->add_option("--max-error", a.auto_args.max_error, "--auto: error bound")->capture_default_str();
  add_auto_choice_options(*c, a.auto_args);
  c->add_option("--metric", a.auto_args.metric, "--auto: metric against s_ref")->capture_default_str();
  c->add_option("--sref-bias", a.auto_args.sref_bias,
                "Depth bias b of s_ref, H(z - d_t + b) against each receiver's plane d_t; sm and pcf run "
                "with it (default 2^-15, the inputs' rounding)")
      ->capture_default_str();
  return c;
}

int run_evaluate(const EvaluateArgs& a) {
  namespace fs = std::filesystem;
  const eval::Grid grid = eval::parse_grid(a.grid);
  const auto methods = eval::parse_methods(a.methods);
  {
    std::string m = a.pareto_metric;
    if (m.rfind("hard_", 0) == 0 || m.rfind("soft_", 0) == 0) m = m.substr(5);
    eval::check_metric(m);
  }
  if (a.auto_args.enabled) eval::check_metric(a.auto_args.metric);
  std::error_code ec;
  fs::create_directories(a.out_dir, ec);
  if (!fs::is_directory(a.out_dir)) throw InputError("cannot create output directory '" + a.out_dir + "'");

  std::vector<eval::Scene> scenes;
  for (const auto& d : a.dirs) scenes.push_back(eval::load_scene(d));
  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  eval::TimingSettings timing{a.warmup, a.runs};

  std::vector<eval::Row> all;
  std::vector<eval::Skipped> skipped;
  std::vector<std::string> auto_lines;
  for (const auto& scene : scenes) {
    // Without --auto every lookup runs; with it only what the scene needs (make_grid drops mips
    // and sat when every footprint <= 1).
    const double fp = a.auto_args.enabled ? scene.max_footprint : std::max(scene.max_footprint, 2.0);
    const auto configs = eval::make_grid(methods, grid, fp, a.auto_args.sref_bias);
    eval::SrefCache sref(scene, a.auto_args.sref_bias);
    std::vector<eval::Row> rows;
    {
      scene::Progress bar(scene.name + " (" + std::to_string(configs.size()) + " configurations)", configs.size(),
                          !a.quiet);
      for (const auto& o : configs) {
        try {
          rows.push_back(eval::evaluate_config(runtime, scene, o, sref, timing));
        } catch (const InputError& e) {
          skipped.push_back({scene.name, eval::config_label(o), cli_message(e.what())});
        }
        bar.add(1);
      }
    }
    if (!a.no_images && !rows.empty()) {
      eval::write_pareto_png((fs::path(a.out_dir) / ("pareto_" + scene.name + ".png")).string(), scene.name, rows,
                             a.pareto_metric);
      // Error image of each method's best configuration (lowest pareto metric).
      std::map<std::string, size_t> best;
      for (size_t i = 0; i < rows.size(); ++i) {
        auto it = best.find(rows[i].method);
        if (it == best.end() ||
            eval::row_metric(rows[i], a.pareto_metric) < eval::row_metric(rows[it->second], a.pareto_metric))
          best[rows[i].method] = i;
      }
      for (const auto& [m, i] : best)
        eval::write_error_png((fs::path(a.out_dir) / ("error_" + scene.name + "_" + m + ".png")).string(), scene,
                              rows[i].visibility, sref.for_options(rows[i].options), 0.25);
    }
    if (a.auto_args.enabled) {
      eval::AutoRequest req;
      req.max_error = a.auto_args.max_error;
      req.metric = a.auto_args.metric;
      req.sref_bias = a.auto_args.sref_bias;
      req.target.blur.radius = a.auto_radius;
      req.lookup_from_scene = a.auto_lookup == "auto";
      req.target.lookup.kind = a.auto_lookup == "mips"  ? Lookup::Mips
                               : a.auto_lookup == "sat" ? Lookup::Sat
                                                        : Lookup::Bilinear;
      req.methods = methods;
      req.timing = timing;
      req.final_rounds = a.auto_args.rounds;
      req.time_tolerance = a.auto_args.tolerance;
      const auto r = eval::choose_auto(runtime, scene, req);
      auto_lines.push_back("== " + scene.name + "\n" + eval::describe(r, req.metric));
    }
    for (auto& r : rows) {
      r.visibility.clear();
      r.visibility.shrink_to_fit();
      all.push_back(std::move(r));
    }
  }
  eval::write_csv((fs::path(a.out_dir) / "results.csv").string(), all);
  eval::write_json((fs::path(a.out_dir) / "results.json").string(), all, skipped, runtime->info().device_name);
  if (a.auto_args.enabled) {
    const std::string path = (fs::path(a.out_dir) / "auto.txt").string();
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) throw InputError("cannot write '" + path + "'");
    for (const auto& l : auto_lines) std::fputs(l.c_str(), f);
    std::fclose(f);
  }

  if (!a.quiet) {
    // acne% / leak%: eval::acne_leak against reference_hard (-1 without one).
    std::printf("%-10s %-34s %9s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "config", "ms", "p99", "rmse", "max",
                "hard_rmse", "acne%", "leak%", "MiB");
    for (const auto& r : all)
      std::printf("%-10s %-34s %9.3f %9.4f %9.4f %9.4f %9.4f %9.2f %9.2f %9.2f\n", r.scene.c_str(), r.label.c_str(),
                  r.time_ms, r.sref.p99, r.sref.rmse, r.sref.max, r.hard.valid ? r.hard.rmse : -1.0,
                  r.acne_leak.valid ? 100.0 * r.acne_leak.acne : -1.0,
                  r.acne_leak.valid ? 100.0 * r.acne_leak.leak : -1.0, r.device_bytes / 1048576.0);
    for (const auto& s : skipped)
      std::printf("skipped %s / %s: %s\n", s.scene.c_str(), s.label.c_str(), s.reason.c_str());
  }
  for (const auto& l : auto_lines) std::fputs(l.c_str(), stdout);
  if (!a.quiet) {
    std::printf("shadowfilter evaluate: %zu configurations on %zu scenes, device %s -> %s\n", all.size(), scenes.size(),
                runtime->info().device_name.c_str(), a.out_dir.c_str());
  }
  return 0;
}

}  // namespace sf::cli

// `shadowfilter evaluate DIR... -o OUT`: every method over a parameter grid on scene directories;
// results.csv / results.json, per scene the Pareto plots (pareto_<scene>.png against the plot's
// reference, pareto_<scene>_<reference>.png against each other one), the contact sheet
// contact_<scene>.png and one error image per method (host/eval).
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "option_names.hpp"
#include "output_file.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"
#include "verbose.hpp"

namespace sf::cli {

CLI::App* add_evaluate_command(CLI::App& app, EvaluateArgs& a) {
  CLI::App* c = app.add_subcommand("evaluate",
                                   "Run methods over a parameter grid on scene directories: time, memory and errors "
                                   "against the ray-traced references, a target filter's s_ref and each "
                                   "configuration's own s_ref; CSV, JSON, Pareto plots and contact sheets");
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
                "Error axis of the plots and the contact sheets: rmse | p99 | max | frac_1_255 | frac_005 | leak | "
                "darken, against --pareto-reference; soft_METRIC, hard_METRIC, target_METRIC or self_METRIC "
                "also names the reference")
      ->capture_default_str();
  c->add_option("--pareto-reference", a.pareto_reference,
                "What the plots' errors are measured against, the same for every configuration: soft (the "
                "ray-traced reference_soft.exr, default) | hard (reference_hard.exr) | target (s_ref of "
                "--target-blur-radius / --target-lookup) | self (each configuration's own s_ref: fidelity, "
                "sm and pcf 0 by definition). A scene without the ray-traced image falls back to target")
      ->check(CLI::IsMember({"soft", "hard", "target", "self"}));
  c->add_option("--target-blur-radius", a.target_blur_radius,
                "Gaussian radius of the target filter (the filter a renderer wants; its s_ref is the target "
                "reference)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_option("--target-lookup", a.target_lookup, "Lookup of the target filter: bilinear | mips | sat")
      ->capture_default_str()
      ->check(CLI::IsMember({"bilinear", "mips", "sat"}));
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
  // The plots' reference: --pareto-reference, or the one a prefixed --pareto-metric names
  // (the older spelling, "hard_rmse"); both at once must agree.
  std::string metric;
  eval::Reference requested = eval::Reference::Soft, prefixed = eval::Reference::Soft;
  const bool has_prefix = eval::split_metric(a.pareto_metric, &metric, &prefixed);
  eval::check_metric(metric);
  if (!a.pareto_reference.empty()) requested = eval::parse_reference(a.pareto_reference);
  if (has_prefix) {
    if (!a.pareto_reference.empty() && prefixed != requested)
      throw InputError("--pareto-metric " + a.pareto_metric + " names the reference '" +
                       eval::reference_name(prefixed) + "', --pareto-reference says '" + a.pareto_reference + "'");
    requested = prefixed;
  }
  eval::TargetFilter target;
  target.blur.radius = a.target_blur_radius;
  target.lookup = a.target_lookup == "bilinear" ? Lookup::Bilinear
                  : a.target_lookup == "sat"    ? Lookup::Sat
                                                : Lookup::Mips;
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
    // One s_ref of the target filter per scene, the same reference for every configuration.
    const std::vector<double>& target_ref = sref.get(target.blur, target.lookup);
    std::vector<eval::Row> rows;
    {
      scene::Progress bar(scene.name + " (" + std::to_string(configs.size()) + " configurations)", configs.size(),
                          !a.quiet);
      for (const auto& o : configs) {
        try {
          rows.push_back(eval::evaluate_config(runtime, scene, o, sref, timing, &target_ref));
        } catch (const InputError& e) {
          skipped.push_back({scene.name, eval::config_label(o), cli_message(e.what())});
        }
        bar.add(1);
      }
    }
    std::string note;
    const eval::Reference ref = eval::plot_reference(scene, requested, &note);
    if (!note.empty()) std::fprintf(stderr, "shadowfilter evaluate: %s\n", note.c_str());
    if (!a.no_images && !rows.empty()) {
      const fs::path out(a.out_dir);
      auto plot = [&](eval::Reference r, const std::string& file) {
        eval::write_pareto_png((out / file).string(), rows, r, metric,
                               eval::pareto_labels(scene, rows.size(), r, metric, target, r == ref ? note : ""));
      };
      plot(ref, "pareto_" + scene.name + ".png");
      for (eval::Reference r :
           {eval::Reference::Soft, eval::Reference::Hard, eval::Reference::Target, eval::Reference::Self})
        if (r != ref && eval::has_reference(scene, r))
          plot(r, "pareto_" + scene.name + "_" + eval::reference_name(r) + ".png");
      const eval::Reference sheet = eval::contact_reference(scene, ref);
      eval::write_contact_sheet((out / ("contact_" + scene.name + ".png")).string(), scene, rows,
                                eval::best_per_method(rows, sheet, metric), sheet, metric, target, target_ref);
      // |v - s_ref| of each method's most faithful configuration (lowest metric against its own
      // s_ref): where a method departs from the filter it was asked for.
      for (size_t i : eval::best_per_method(rows, eval::Reference::Self, metric))
        eval::write_error_png((out / ("error_" + scene.name + "_" + rows[i].method + ".png")).string(), scene,
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
  eval::write_csv((fs::path(a.out_dir) / "results.csv").string(), all, target);
  eval::write_json((fs::path(a.out_dir) / "results.json").string(), all, skipped, runtime->info().device_name, target);
  if (a.auto_args.enabled) {
    std::string text;
    for (const auto& l : auto_lines) text += l;
    io::write_text((fs::path(a.out_dir) / "auto.txt").string(), "results file", text);
  }

  if (!a.quiet) {
    // RMSE against each reference (-1 where the scene has none; self: the configuration's own
    // s_ref, a fidelity figure); acne% / leak%: eval::acne_leak against reference_hard.
    std::printf("%-10s %-34s %9s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "config", "ms", "soft_rmse", "hard_rmse",
                "tgt_rmse", "self_rmse", "acne%", "leak%", "MiB");
    auto rmse = [](const eval::ErrorStats& e) { return e.valid ? e.rmse : -1.0; };
    for (const auto& r : all)
      std::printf("%-10s %-34s %9.3f %9.4f %9.4f %9.4f %9.4f %9.2f %9.2f %9.2f\n", r.scene.c_str(), r.label.c_str(),
                  r.time_ms, rmse(r.soft), rmse(r.hard), rmse(r.target), rmse(r.sref),
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

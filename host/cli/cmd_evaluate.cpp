// `shadowfilter evaluate DIR... -o OUT`: its options, turned into an eval::EvaluationRequest
// (host/eval/evaluation.hpp, which runs it and writes the files), and the summary it prints.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "evaluation.hpp"
#include "option_names.hpp"
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
  c->add_option("--methods", a.methods,
                "'all' (every non-soft method), 'soft' (pcss, cssm, ssmm, ssmm-improved, under the scene's area "
                "light) or a comma-separated list of both kinds")
      ->capture_default_str();
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
  c->add_flag("--frames", a.frames,
              "The scene directories are consecutive frames seen from one still camera (a moving light): "
              "flicker per configuration in results_frames.csv, results_frames.md and flicker.png");
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
  const eval::Grid grid = eval::parse_grid(a.grid);
  const eval::MethodLists methods = eval::parse_evaluated_methods(a.methods);
  if (a.auto_args.enabled && methods.hard.empty())
    throw InputError("--auto chooses among the non-soft methods: --methods names none");
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
  eval::EvaluationRequest q;
  q.dirs = a.dirs;
  q.out_dir = a.out_dir;
  q.methods = methods.hard;
  q.soft_methods = methods.soft;
  q.grid = grid;
  q.reference = requested;
  q.metric = metric;
  q.target.blur.radius = a.target_blur_radius;
  q.target.lookup = a.target_lookup == "bilinear" ? Lookup::Bilinear
                    : a.target_lookup == "sat"    ? Lookup::Sat
                                                  : Lookup::Mips;
  q.timing = eval::TimingSettings{a.warmup, a.runs};
  q.sref_bias = a.auto_args.sref_bias;
  q.images = !a.no_images;
  q.frames = a.frames;
  q.progress = !a.quiet;
  q.describe_refusal = cli_message;
  if (a.auto_args.enabled) {
    eval::check_metric(a.auto_args.metric);
    eval::AutoRequest req;
    req.max_error = a.auto_args.max_error;
    req.metric = a.auto_args.metric;
    req.sref_bias = a.auto_args.sref_bias;
    req.target.blur.radius = a.auto_radius;
    req.lookup_from_scene = a.auto_lookup == "auto";
    req.target.lookup.kind = a.auto_lookup == "mips"  ? Lookup::Mips
                             : a.auto_lookup == "sat" ? Lookup::Sat
                                                      : Lookup::Bilinear;
    req.final_rounds = a.auto_args.rounds;
    req.time_tolerance = a.auto_args.tolerance;
    q.auto_request = req;
  }
  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  const eval::EvaluationResult r = eval::run_evaluation(q, runtime, std::cerr);
  if (!a.quiet) std::cout << eval::summary_table(r);
  if (!a.quiet && !r.flicker.empty()) std::cout << eval::flicker_markdown(r.flicker, r.flicker_reference);
  for (const auto& l : r.auto_lines) std::cout << l;
  if (!a.quiet)
    std::cout << "shadowfilter evaluate: " << r.rows.size() << " configurations on " << r.scenes << " scenes, device "
              << r.device_name << " -> " << a.out_dir << "\n";
  return 0;
}

}  // namespace sf::cli

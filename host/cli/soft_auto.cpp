// `soft --auto`: the fastest soft configuration under an error bound against the user's own
// soft reference (eval::choose_soft_auto). The soft methods filter with the light's footprint, so
// there is no exact filtered test to aim at as filter --auto has: the target is an image the
// user trusts (a ray-traced render of the same receivers, or a scene's reference_soft.exr).
#include <iostream>

#include "evaluate.hpp"
#include "options_soft.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {

void add_soft_auto_options(CLI::App& c, SoftArgs& a) {
  CLI::Option* on =
      c.add_flag("--auto", a.auto_args.enabled,
                 "Pick the fastest soft configuration (evaluate's soft grid: the method and its parameters) whose "
                 "error against --reference stays under --max-error on this input; prints what it chose and why");
  c.add_option("--reference", a.reference,
               "--auto: the exact soft visibility of these receivers, one channel of their size (a ray-traced "
               "render, or a scene's reference_soft.exr)");
  c.add_option("--max-error", a.auto_args.max_error, "--auto: error bound in [0, 1]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c.add_option("--metric", a.auto_args.metric,
               "--auto: error metric against --reference over the receivers facing the light: rmse | p99 | max | "
               "frac_1_255 | frac_005 | leak | darken")
      ->capture_default_str();
  c.add_option("--auto-methods", a.auto_args.methods,
               "--auto: candidate methods, 'soft' (all four) or a comma list of pcss, cssm, ssmm, ssmm-improved")
      ->capture_default_str();
  c.add_option("--auto-grid", a.auto_grid, "--auto: the parameters tried, quick | default | wide (evaluate's grid)")
      ->capture_default_str();
  c.add_option("--auto-runs", a.auto_args.runs, "--auto: timed runs per candidate and per final round")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  add_auto_choice_options(c, a.auto_args);
  // What the grid sets: giving it too would be silently overridden.
  for (const char* grid_set : {"--method", "--lookup", "--cssm-order", "--ssmm-n", "--cssm-storage"})
    c.get_option(grid_set)->excludes(on);
}

SoftOptions choose_soft_auto_options(const SoftArgs& a, const SoftLightInput& light, const SoftOptions& base,
                                     const std::shared_ptr<Runtime>& runtime, nlohmann::json& summary) {
  eval::SoftAutoRequest req;
  req.max_error = a.auto_args.max_error;
  req.metric = a.auto_args.metric;
  eval::check_metric(req.metric);
  const eval::MethodLists lists = eval::parse_evaluated_methods(a.auto_args.methods);
  if (!lists.hard.empty())
    throw InputError("--auto-methods: soft --auto chooses among pcss, cssm, ssmm and ssmm-improved; '" +
                     lists.hard.front() + "' is a method of filter");
  req.methods = lists.soft;
  req.grid = eval::parse_grid(a.auto_grid);
  req.base = base;
  req.timing.runs = a.auto_args.runs;
  req.final_rounds = a.auto_args.rounds;
  req.time_tolerance = a.auto_args.tolerance;
  req.reference = "soft reference '" + a.reference + "'";
  eval::Scene scene = eval::make_scene("input", light.depth, light.receivers);
  scene.light = light.light;
  scene.ref_soft = eval::load_soft_reference(a.reference);
  const bool talk = !a.quiet && !a.json;
  std::unique_ptr<scene::Progress> bar;
  const eval::AutoResult r = eval::choose_soft_auto(runtime, scene, req, [&](size_t, size_t total) {
    if (!bar) bar = std::make_unique<scene::Progress>("auto", total, talk);
    bar->add(1);
  });
  bar.reset();
  const std::string text = eval::describe(r, req.metric);
  if (talk) std::cout << text;
  if (!r.found) {
    std::string closest;
    const eval::Row* best = nullptr;
    for (const auto& row : r.tried)
      if (!best || eval::metric_value(row.soft, req.metric) < eval::metric_value(best->soft, req.metric)) best = &row;
    if (best)
      closest = " (closest: " + best->label + ", " + req.metric + " " +
                std::to_string(eval::metric_value(best->soft, req.metric)) + ")";
    throw InputError("--auto: no soft configuration meets " + req.metric + " <= " + std::to_string(req.max_error) +
                     closest);
  }
  const eval::Row& c = r.chosen_row;
  summary = {{"chosen", c.label},          {"metric", req.metric},    {"error", eval::metric_value(c.soft, req.metric)},
             {"max_error", req.max_error}, {"tried", r.tried.size()}, {"finalists", r.finalists.size()}};
  return *c.soft_options;
}

}  // namespace sf::cli

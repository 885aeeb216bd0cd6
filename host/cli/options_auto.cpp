// --auto for `filter` (and the flags `evaluate --auto` shares): the fastest configuration whose
// error against s_ref of the requested weights stays under --max-error on this input.
#include <iostream>

#include "commands.hpp"
#include "evaluate.hpp"
#include "print.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {

void add_auto_choice_options(CLI::App& c, AutoArgs& a) {
  c.add_option("--auto-rounds", a.rounds,
               "--auto: interleaved rounds in which the candidates under the bound run again; each keeps its "
               "fastest run")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  c.add_option("--auto-tolerance", a.tolerance,
               "--auto: least tie band: fastest runs within this fraction (or the measured noise, when larger) "
               "of the fastest are a tie, which goes to the lower estimated cost")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
}

void add_auto_options(CLI::App& c, AutoArgs& a) {
  c.add_flag("--auto", a.enabled,
             "Pick the fastest method configuration whose error against s_ref (the exact filtered "
             "test with the requested --blur-radius / --lookup weights) stays under --max-error on "
             "this input; prints what it chose and skipped");
  c.add_option("--max-error", a.max_error, "--auto: error bound in [0, 1] (default 0.05)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c.add_option("--metric", a.metric,
               "--auto: error metric against s_ref: p99 | rmse | max | frac_1_255 | frac_005 | leak | darken")
      ->capture_default_str();
  c.add_option("--auto-methods", a.methods, "--auto: candidate methods, 'all' or a comma list")->capture_default_str();
  c.add_option("--auto-runs", a.runs, "--auto: timed runs per candidate and per final round")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  add_auto_choice_options(c, a);
  c.add_option("--sref-bias", a.sref_bias,
               "--auto: depth bias b of s_ref, H(z - d_t + b) against each receiver's plane (default 2^-15)")
      ->capture_default_str();
}

FilterOptions choose_auto_options(const FilterArgs& a, const HostImage& depth, const Receivers& receivers,
                                  const std::shared_ptr<Runtime>& runtime) {
  eval::check_metric(a.auto_args.metric);
  eval::AutoRequest req;
  req.max_error = a.auto_args.max_error;
  req.metric = a.auto_args.metric;
  req.sref_bias = a.auto_args.sref_bias;
  req.target = a.options;
  req.methods = eval::parse_methods(a.auto_args.methods);
  req.timing.runs = std::max(1, a.auto_args.runs);
  req.final_rounds = a.auto_args.rounds;
  req.time_tolerance = a.auto_args.tolerance;
  const eval::Scene scene = eval::make_scene("input", depth, receivers);
  std::unique_ptr<scene::Progress> bar;
  const eval::AutoResult r = eval::choose_auto(runtime, scene, req, [&](size_t done, size_t total) {
    if (!bar) bar = std::make_unique<scene::Progress>("auto", total, !a.quiet);
    bar->add(1);
  });
  bar.reset();
  if (!r.found) {
    std::cerr << eval::describe(r, req.metric);
    throw InputError("--auto: no configuration meets " + req.metric + " <= " + std::to_string(req.max_error));
  }
  std::cout << eval::describe(r, req.metric);
  FilterOptions chosen = r.chosen;
  chosen.schedule = a.options.schedule;
  return chosen;
}

}  // namespace sf::cli

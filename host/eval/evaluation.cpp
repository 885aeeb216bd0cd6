#include "evaluation.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <system_error>

#include "output_file.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {
namespace {

namespace fs = std::filesystem;

// The Pareto plots, the contact sheet and each method's error image of one scene.
void write_scene_images(const EvaluationRequest& q, const Scene& scene, const std::vector<Row>& rows, SrefCache& sref,
                        const std::vector<double>& target_ref, Reference ref, const std::string& note) {
  const fs::path out(q.out_dir);
  auto plot = [&](Reference r, const std::string& file) {
    write_pareto_png((out / file).string(), rows, r, q.metric,
                     pareto_labels(scene, rows.size(), r, q.metric, q.target, r == ref ? note : ""));
  };
  plot(ref, "pareto_" + scene.name + ".png");
  for (Reference r : {Reference::Soft, Reference::Hard, Reference::Target, Reference::Self})
    if (r != ref && has_reference(scene, r)) plot(r, "pareto_" + scene.name + "_" + reference_name(r) + ".png");
  const Reference sheet = contact_reference(scene, ref);
  write_contact_sheet((out / ("contact_" + scene.name + ".png")).string(), scene, rows,
                      best_per_method(rows, sheet, q.metric), sheet, q.metric, q.target, target_ref);
  // |v - s_ref| of each method's most faithful configuration (lowest metric against its own
  // s_ref): where a method departs from the filter it was asked for.
  for (size_t i : best_per_method(rows, Reference::Self, q.metric))
    write_error_png((out / ("error_" + scene.name + "_" + rows[i].method + ".png")).string(), scene, rows[i].visibility,
                    sref.for_options(rows[i].options), 0.25);
}

}  // namespace

EvaluationResult run_evaluation(const EvaluationRequest& q, const std::shared_ptr<Runtime>& runtime,
                                std::ostream& notes) {
  std::error_code ec;
  fs::create_directories(q.out_dir, ec);
  if (!fs::is_directory(q.out_dir)) throw InputError("cannot create output directory '" + q.out_dir + "'");
  std::vector<Scene> scenes;
  for (const auto& d : q.dirs) scenes.push_back(load_scene(d));
  std::optional<FlickerTracker> flicker;
  if (q.frames) {
    if (scenes.size() < 2) throw InputError("--frames needs at least two scene directories, one per frame, in order");
    flicker.emplace();
    for (const auto& scene : scenes) flicker->check_frame(scene);  // every frame before anything runs
  }

  EvaluationResult result;
  result.scenes = scenes.size();
  result.device_name = runtime->info().device_name;
  for (const auto& scene : scenes) {
    // Without --auto every lookup runs; with it only what the scene needs (make_grid drops mips
    // and sat when every footprint <= 1).
    const double fp = q.auto_request ? scene.max_footprint : std::max(scene.max_footprint, 2.0);
    const auto configs = make_grid(q.methods, q.grid, fp, q.sref_bias, scene.receivers.has_jacobian);
    const auto soft_configs = make_soft_grid(q.soft_methods, q.grid);
    SrefCache sref(scene, q.sref_bias);
    // One s_ref of the target filter per scene, the same reference for every configuration.
    const std::vector<double>& target_ref = sref.get(q.target.blur, q.target.lookup);
    std::vector<Row> rows;
    {
      const size_t total = configs.size() + soft_configs.size();
      scene::Progress bar(scene.name + " (" + std::to_string(total) + " configurations)", total, q.progress);
      for (const auto& o : configs) {
        try {
          rows.push_back(evaluate_config(runtime, scene, o, sref, q.timing, &target_ref));
        } catch (const InputError& e) {
          result.skipped.push_back({scene.name, config_label(o), q.describe_refusal(e.what())});
        }
        bar.add(1);
      }
      // The soft methods under the scene's light: errors against the ray-traced references only.
      for (const auto& o : soft_configs) {
        try {
          rows.push_back(evaluate_soft_config(runtime, scene, o, q.timing));
        } catch (const InputError& e) {
          result.skipped.push_back({scene.name, soft_label(o), q.describe_refusal(e.what())});
        }
        bar.add(1);
      }
    }
    std::string note;
    const Reference ref = plot_reference(scene, q.reference, &note);
    if (!note.empty()) notes << "shadowfilter evaluate: " << note << "\n";
    if (q.images && !rows.empty()) write_scene_images(q, scene, rows, sref, target_ref, ref, note);
    if (q.auto_request) {
      AutoRequest req = *q.auto_request;
      req.methods = q.methods;
      req.timing = q.timing;
      const auto r = choose_auto(runtime, scene, req);
      result.auto_lines.push_back("== " + scene.name + "\n" + describe(r, req.metric));
    }
    if (flicker) flicker->add_frame(scene, rows);
    for (auto& r : rows) {
      r.visibility.clear();
      r.visibility.shrink_to_fit();
      result.rows.push_back(std::move(r));
    }
  }
  write_csv((fs::path(q.out_dir) / "results.csv").string(), result.rows, q.target);
  write_json((fs::path(q.out_dir) / "results.json").string(), result.rows, result.skipped, result.device_name,
             q.target);
  if (flicker) {
    result.flicker = flicker->rows();
    result.flicker_reference = flicker->reference();
    const fs::path out(q.out_dir);
    write_flicker_csv((out / "results_frames.csv").string(), result.flicker, result.flicker_reference);
    io::write_text((out / "results_frames.md").string(), "results file",
                   flicker_markdown(result.flicker, result.flicker_reference));
    if (q.images)
      write_flicker_png((out / "flicker.png").string(), result.flicker, result.flicker_reference, int(scenes.size()));
  }
  if (q.auto_request) {
    std::string text;
    for (const auto& l : result.auto_lines) text += l;
    io::write_text((fs::path(q.out_dir) / "auto.txt").string(), "results file", text);
  }
  return result;
}

std::string summary_table(const EvaluationResult& result) {
  std::string text;
  char line[512];
  // RMSE against each reference (-1 where the scene has none; self: the configuration's own
  // s_ref, a fidelity figure); acne% / leak%: acne_leak against reference_hard.
  std::snprintf(line, sizeof line, "%-10s %-34s %9s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "config", "ms",
                "soft_rmse", "hard_rmse", "tgt_rmse", "self_rmse", "acne%", "leak%", "MiB");
  text += line;
  auto rmse = [](const ErrorStats& e) { return e.valid ? e.rmse : -1.0; };
  for (const auto& r : result.rows) {
    std::snprintf(line, sizeof line, "%-10s %-34s %9.3f %9.4f %9.4f %9.4f %9.4f %9.2f %9.2f %9.2f\n", r.scene.c_str(),
                  r.label.c_str(), r.time_ms, rmse(r.soft), rmse(r.hard), rmse(r.target), rmse(r.sref),
                  r.acne_leak.valid ? 100.0 * r.acne_leak.acne : -1.0,
                  r.acne_leak.valid ? 100.0 * r.acne_leak.leak : -1.0, r.device_bytes / 1048576.0);
    text += line;
  }
  for (const auto& s : result.skipped) text += "skipped " + s.scene + " / " + s.label + ": " + s.reason + "\n";
  return text;
}

}  // namespace sf::eval

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "commands.hpp"
#include "filter_options.hpp"
#include "help_format.hpp"
#include "image_io.hpp"
#include "output_file.hpp"
#include "json_summary.hpp"
#include "preview_images.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::cli {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

}  // namespace

CLI::App* add_filter_command(CLI::App& app, FilterArgs& a) {
  CLI::App* c = app.add_subcommand("filter", "Filter a shadow map and write the visibility of receivers");
  auto* map = c->add_option("--shadow-map", a.shadow_maps,
                            "Depth map (EXR, TIFF, PFM, 16-bit PNG, HDR), one channel (or one named Z), at least "
                            "16 bits; several with --output-dir");
  auto* rx = c->add_option("--receivers", a.receivers, "Receiver image (the format below)");
  auto* rd = c->add_option("--receiver-depth", a.receiver_depth,
                           "Planar receivers: a depth image of the map's size, one receiver per texel");
  rx->excludes(rd);
  rd->excludes(rx);
  auto* out = c->add_option("-o,--output", a.output, "Visibility image (.exr, .tif, .pfm, .png)");
  auto* frames = c->add_option("--frames", a.frames,
                               "Batch: a list of frames, one a line: SHADOWMAP (RECEIVERS | depth=RECEIVER_DEPTH | "
                               "camera=CAMERA.json camera-depth=DEPTH) [light=LIGHT.json] OUTPUT (paths relative to "
                               "the list, '#' comments; docs/batch.md)");
  auto* dir = c->add_option("--output-dir", a.output_dir,
                            "Batch: one output DIR/<map's stem>.exr per --shadow-map, the receivers shared");
  frames->excludes(map)->excludes(rx)->excludes(rd)->excludes(out)->excludes(dir);
  dir->excludes(out);
  c->add_option("--cascades", a.cascades,
                "Layered maps: a directory of cascade_0.exr, cascade_1.exr, ... or a comma-separated list of "
                "layer files (each a depth map whose header holds its matrix and split); needs --view");
  c->add_option("--view", a.view,
                "With --cascades: the camera view's receivers (P.x P.y P.z depth dPdx.* dPdy.* [ndl])");
  c->add_option("--cascade-blend", a.cascade_blend,
                "With --cascades: the blend band between layers, a fraction of each layer's depth range in "
                "[0, 1) (default: the files')");
  c->add_flag("--keep-going", a.keep_going,
              "Batch: report a failed frame and carry on (the exit code is the number of failed frames)");
  c->add_option("--shard", a.shard,
                "Batch: run part K of N (frames K, K + N, K + 2N, ... of the list; 1 <= K <= N): N processes with "
                "K = 1..N write what one run writes")
      ->type_name("K/N");
  c->add_option("--preview", a.preview,
                "Also write OUTPUT.png (the visibility, 16-bit grey); shaded: and OUTPUT_shaded.png beside it (a "
                "grey surface lit by the light, the background in blue)")
      ->expected(0, 1)
      ->type_name("[shaded]");
  add_method_options(*c, a.options);
  add_prefilter_options(*c, a.options);
  add_depth_options(*c, a.inputs);
  add_camera_options(*c, a.inputs);
  c->add_option("--device", a.device,
                "OpenCL device: P:D, index, gpu, cpu or a name substring "
                "(default: $SHADOWFILTER_DEVICE, else first GPU, else CPU)");
  c->add_option("--vector-width", a.options.schedule.blur_vector_width, "Blur texels per work-item (4, 8, 16)")
      ->capture_default_str()
      ->check(CLI::IsMember({4, 8, 16}));
  const std::map<std::string, ScheduleFamily> schedules{
      {"auto", ScheduleFamily::Auto}, {"cpu", ScheduleFamily::Cpu}, {"gpu", ScheduleFamily::Gpu}};
  c->add_option("--schedule", a.options.schedule.family,
                "Launch shapes of the blur, SAT and pyramid: auto (by device type), cpu or gpu")
      ->transform(named_values(schedules))
      ->type_name(value_names(schedules))
      ->default_str("auto");
  c->add_option("--flags-out", a.flags_out,
                "With --esm-classify: write the mask of flagged receivers (1 = flagged) here");
  c->add_flag("-q,--quiet", a.quiet, "Do not print the summary line");
  c->add_flag("--json", a.json, "Print the summary as one JSON object instead of a line of text");
  add_verbose_flag(*c, a.verbose);
  add_auto_options(*c, a.auto_args);
  c->footer(std::string(kReceiverFormatHelp) + "\n\n" +
            "Examples:\n"
            "  shadowfilter filter --shadow-map data/spheres/shadowmap.exr --receivers data/spheres/receivers.exr "
            "-o vis.exr --preview shaded\n"
            "  shadowfilter filter --shadow-map sun_depth.exr --light sun.json --camera camera.json --camera-depth "
            "camera_depth.exr -o vis.exr --method pcf --blur-radius 2\n"
            "  shadowfilter filter --shadow-map depth.exr --encoding perspective --near 0.5 --far 40 --receivers "
            "rx.exr -o vis.exr\n"
            "Your own depth buffers, their encodings and the common mistakes: docs/inputs.md");
  return c;
}

int run_filter(const FilterArgs& a) {
  if (!a.cascades.empty() || !a.view.empty() || !std::isnan(a.cascade_blend)) return run_filter_layered(a);
  if (!a.frames.empty() || !a.output_dir.empty()) return run_filter_batch(a);
  const auto t0 = Clock::now();
  if (a.shadow_maps.size() != 1)
    throw InputError(a.shadow_maps.empty() ? "give --shadow-map (or --frames LIST)"
                                           : "several --shadow-map files need --output-dir DIR (or use --frames LIST)");
  const std::string& shadow_map = a.shadow_maps.front();
  if (a.output.empty()) throw InputError("give -o/--output (or --output-dir DIR, or --frames LIST)");
  if (a.keep_going) throw InputError("--keep-going is for a batch (--frames or --output-dir)");
  if (!a.shard.empty()) throw InputError("--shard is for a batch (--frames or --output-dir)");
  const FrameFiles files{shadow_map,      a.receivers,           a.receiver_depth,
                         a.inputs.camera, a.inputs.camera_depth, a.inputs.light};
  require_one_receiver_source(files);
  validate_depth_args(a.inputs);
  const PreviewKind preview = parse_preview(a.preview);
  const std::vector<std::string> inputs{shadow_map,      a.receivers,           a.receiver_depth,
                                        a.inputs.camera, a.inputs.camera_depth, a.inputs.light,
                                        a.inputs.normals};
  if (!a.flags_out.empty() && classify_mode(a.options) == EsmClassify::None)
    throw InputError("--flags-out needs a classification (--method esm, or --esm-classify zmax or threshold)");
  std::vector<std::string> output_files = preview_paths(a.output, preview);
  output_files.insert(output_files.begin(), a.output);
  output_files.push_back(a.flags_out);
  io::check_outputs(output_files, inputs);

  const FrameInputs in = load_frame(files, a.inputs);
  const HostImage& depth = in.depth;
  const Receivers& receivers = in.receivers;
  const double load_ms = ms_since(t0);

  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  const FilterOptions options = a.auto_args.enabled ? choose_auto_options(a, depth, receivers, runtime) : a.options;
  const auto t_run = Clock::now();
  FilterResult r = filter(runtime, options, depth, receivers);
  const double run_ms = ms_since(t_run);

  const auto t_write = Clock::now();
  // The visibility, its previews and the flags appear together or not at all.
  HostImage shaded;
  std::vector<io::ImageToWrite> outputs =
      output_with_previews(a.output, r.visibility, preview, receivers.d, receivers.ndl, &shaded);
  if (!a.flags_out.empty()) outputs.push_back({a.flags_out, &r.flags});
  io::write_images(outputs);
  const double write_ms = ms_since(t_write);
  print_warnings(in.warnings);

  const size_t lit_able = receivers.count() - r.background - r.outside;
  if (a.quiet) return 0;
  if (a.json) {
    nlohmann::json j;
    j["command"] = "filter";
    j["filter"] = filter_options_json(options);
    j["map"] = {{"file", shadow_map}, {"width", depth.width}, {"height", depth.height}};
    j["receivers"] = {{"width", receivers.width},    {"height", receivers.height}, {"planar", receivers.grid},
                      {"count", receivers.count()},  {"background", r.background}, {"outside", r.outside},
                      {"facing_away", r.facing_away}};
    if (r.classified) j["flagged"] = {{"count", r.flagged}, {"in_map", lit_able}};
    j["device"] = runtime->info().device_name;
    j["device_ms"] = stage_ms_json(r.times);
    j["wall_ms"] = {{"load", load_ms}, {"run", run_ms}, {"write", write_ms}, {"total", ms_since(t0)}};
    nlohmann::json written = nlohmann::json::array();
    for (const io::ImageToWrite& o : outputs) written.push_back(o.path);
    j["outputs"] = written;
    j["warnings"] = in.warnings;
    print_json(j);
    return 0;
  }
  // Footprint-lookup and classification stages (only those that ran), and the flagged fraction
  // of all receivers (the seed's table 7.2 counts screen pixels the same way).
  char flagged[128] = "";
  std::string stages;
  auto stage = [&stages](const char* name, double seconds) {
    char b[48];
    std::snprintf(b, sizeof b, ", %s %.3f", name, seconds * 1e3);
    stages += b;
  };
  if (r.times.pyramid > 0) stage("mips", r.times.pyramid);
  if (r.times.sat > 0) stage("sat", r.times.sat);
  if (r.times.zmax > 0) stage("zmax", r.times.zmax);
  if (r.classified) stage("classify", r.times.classify);
  if (r.classified)
    std::snprintf(flagged, sizeof flagged, " | flagged %.2f%% of receivers, %.2f%% of %zu in the map",
                  receivers.count() ? 100.0 * r.flagged / receivers.count() : 0.0,
                  lit_able ? 100.0 * r.flagged / lit_able : 0.0, lit_able);
  std::cout << formatted(
      "shadowfilter: %s | map %dx%d, receivers %dx%d%s (%zu background, %zu outside, %zu facing away)%s | "
      "device %s | "
      "device ms: transform %.3f, blur %.3f%s, reconstruct %.3f, upload %.3f, download %.3f | "
      "wall ms: load %.1f, run %.1f, write %.1f, total %.1f | %s\n",
      (method_summary(options) + ", " + prefilter_summary(options)).c_str(), depth.width, depth.height, receivers.width,
      receivers.height, receivers.grid ? " (planar)" : "", r.background, r.outside, r.facing_away, flagged,
      runtime->info().device_name.c_str(), r.times.transform * 1e3, r.times.blur * 1e3, stages.c_str(),
      r.times.reconstruct * 1e3, r.times.upload * 1e3, r.times.download * 1e3, load_ms, run_ms, write_ms, ms_since(t0),
      a.output.c_str());
  return 0;
}

}  // namespace sf::cli

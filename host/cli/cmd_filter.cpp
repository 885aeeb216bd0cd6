#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "commands.hpp"
#include "filter_options.hpp"
#include "image_io.hpp"
#include "output_file.hpp"
#include "verbose.hpp"
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
                            "Depth map (EXR, TIFF, PFM, PNG, HDR), one channel; several with --output-dir");
  auto* rx = c->add_option("--receivers", a.receivers,
                           "Receiver image: float EXR/TIFF/PFM with channels u v d [f [ndl]] (or RGB[A[5th]])");
  auto* rd =
      c->add_option("--receiver-depth", a.receiver_depth, "Planar-receiver depth image of the shadow map's size");
  rx->excludes(rd);
  rd->excludes(rx);
  auto* out = c->add_option("-o,--output", a.output, "Visibility image (.exr, .tif, .pfm, .png)");
  auto* frames = c->add_option("--frames", a.frames,
                               "Batch: a list of frames, one a line: SHADOWMAP (RECEIVERS | depth=RECEIVER_DEPTH) "
                               "OUTPUT (paths relative to the list, '#' comments)");
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
  c->add_flag("--preview", a.preview, "Also write OUTPUT.png, the visibility as a 16-bit grey PNG");
  add_method_options(*c, a.options);
  add_prefilter_options(*c, a.options);
  c->add_option("--encoding", a.encoding, "Depth encoding of the inputs: linear|perspective|reversed")
      ->capture_default_str();
  c->add_option("--near", a.near_plane, "Near plane (perspective/reversed encodings)")->capture_default_str();
  c->add_option("--far", a.far_plane, "Far plane (perspective/reversed encodings)")->capture_default_str();
  c->add_option("--nonfinite", a.nonfinite, "Non-finite shadow-map texels: error|far")->capture_default_str();
  c->add_option("--device", a.device,
                "OpenCL device: P:D, index, gpu, cpu or a name substring "
                "(default: $SHADOWFILTER_DEVICE, else first GPU, else CPU)");
  c->add_option("--vector-width", a.options.schedule.blur_vector_width, "Blur texels per work-item (4, 8, 16)")
      ->capture_default_str()
      ->check(CLI::IsMember({4, 8, 16}));
  c->add_option("--schedule", a.options.schedule.family,
                "Launch shapes of the blur, SAT and pyramid: auto (by device type), cpu or gpu")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, ScheduleFamily>{
              {"auto", ScheduleFamily::Auto}, {"cpu", ScheduleFamily::Cpu}, {"gpu", ScheduleFamily::Gpu}},
          CLI::ignore_case))
      ->default_str("auto");
  c->add_option("--flags-out", a.flags_out,
                "With --esm-classify: write the mask of flagged receivers (1 = flagged) here");
  c->add_flag("-q,--quiet", a.quiet, "Do not print the summary line");
  add_verbose_flag(*c, a.verbose);
  add_auto_options(*c, a.auto_args);
  return c;
}

io::DepthLoadOptions depth_load_options(const FilterArgs& a) {
  io::DepthLoadOptions load;
  load.encoding = io::parse_depth_encoding(a.encoding);
  load.near_plane = a.near_plane;
  load.far_plane = a.far_plane;
  if (a.nonfinite == "far")
    load.nonfinite = io::NonFinitePolicy::Far;
  else if (a.nonfinite != "error")
    throw InputError("--nonfinite must be 'error' or 'far', got '" + a.nonfinite + "'");
  return load;
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
  if (a.receivers.empty() == a.receiver_depth.empty())
    throw InputError("give exactly one of --receivers or --receiver-depth");
  const std::string preview = a.preview ? io::preview_path(a.output) : "";
  if (!a.flags_out.empty() && classify_mode(a.options) == EsmClassify::None)
    throw InputError("--flags-out needs a classification (--method esm, or --esm-classify zmax or threshold)");
  io::check_outputs({a.output, preview, a.flags_out}, {shadow_map, a.receivers, a.receiver_depth});

  const io::DepthLoadOptions load = depth_load_options(a);
  const HostImage depth = io::load_depth_map(shadow_map, load);
  const Receivers receivers = io::load_receivers(a.receivers, a.receiver_depth, depth, load);
  const double load_ms = ms_since(t0);

  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  const FilterOptions options = a.auto_args.enabled ? choose_auto_options(a, depth, receivers, runtime) : a.options;
  const auto t_run = Clock::now();
  FilterResult r = filter(runtime, options, depth, receivers);
  const double run_ms = ms_since(t_run);

  const auto t_write = Clock::now();
  // The visibility, its preview and the flags appear together or not at all.
  std::vector<io::ImageToWrite> outputs{{a.output, &r.visibility}};
  if (!preview.empty()) outputs.push_back({preview, &r.visibility});
  if (!a.flags_out.empty()) outputs.push_back({a.flags_out, &r.flags});
  io::write_images(outputs);
  const double write_ms = ms_since(t_write);

  if (!a.quiet) {
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
    if (r.classified) {
      const size_t lit_able = receivers.count() - r.background - r.outside;
      std::snprintf(flagged, sizeof flagged, " | flagged %.2f%% of receivers, %.2f%% of %zu in the map",
                    receivers.count() ? 100.0 * r.flagged / receivers.count() : 0.0,
                    lit_able ? 100.0 * r.flagged / lit_able : 0.0, lit_able);
    }
    std::printf(
        "shadowfilter: %s | map %dx%d, receivers %dx%d%s (%zu background, %zu outside, %zu facing away)%s | "
        "device %s | "
        "device ms: transform %.3f, blur %.3f%s, reconstruct %.3f, upload %.3f, download %.3f | "
        "wall ms: load %.1f, run %.1f, write %.1f, total %.1f | %s\n",
        (method_summary(options) + ", " + prefilter_summary(options)).c_str(), depth.width, depth.height,
        receivers.width, receivers.height, receivers.grid ? " (planar)" : "", r.background, r.outside, r.facing_away,
        flagged, runtime->info().device_name.c_str(), r.times.transform * 1e3, r.times.blur * 1e3, stages.c_str(),
        r.times.reconstruct * 1e3, r.times.upload * 1e3, r.times.download * 1e3, load_ms, run_ms, write_ms,
        ms_since(t0), a.output.c_str());
  }
  return 0;
}

}  // namespace sf::cli

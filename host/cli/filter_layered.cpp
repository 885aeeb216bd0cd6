// `filter --cascades DIR|LIST --view VIEW -o OUT`: a cascade set's layer files filtered layer by
// layer and reconstructed at a camera view's receivers (shadowfilter/layered.hpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "filter_options.hpp"
#include "image_io.hpp"
#include "layered_inputs.hpp"
#include "preview_images.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"

namespace sf::cli {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// What a layered run cannot take: the single-map inputs, the batch and --auto (which measure
// one map), --flags-out (a mask per layer has no one output), and depth encodings (layer files
// hold linear depth, cascade_io.hpp).
void refuse_single_map_options(const FilterArgs& a) {
  const auto refuse = refuse_with_cascades;
  if (a.cascades.empty()) throw InputError("--view and --cascade-blend need --cascades DIR|LIST");
  refuse(!a.shadow_maps.empty(), "--shadow-map");
  refuse(!a.receivers.empty(), "--receivers");
  refuse(!a.receiver_depth.empty(), "--receiver-depth");
  refuse(!a.frames.empty(), "--frames");
  refuse(!a.output_dir.empty(), "--output-dir");
  refuse(a.keep_going, "--keep-going");
  refuse(a.auto_args.enabled, "--auto");
  refuse(!a.flags_out.empty(), "--flags-out");
  refuse(!a.inputs.encoding.empty() || !a.inputs.receiver_encoding.empty() || !std::isnan(a.inputs.near_plane) ||
             !std::isnan(a.inputs.far_plane),
         "--encoding, --receiver-encoding, --near or --far (layer files hold linear depth)");
  refuse(!a.inputs.light.empty() || !a.inputs.camera.empty(), "--light or --camera (the layers hold their matrices)");
  if (a.view.empty()) throw InputError("--cascades needs --view VIEW (the camera view's receivers)");
  if (a.output.empty()) throw InputError("give -o/--output");
}

}  // namespace

int run_filter_layered(const FilterArgs& a) {
  const auto t0 = Clock::now();
  refuse_single_map_options(a);
  const PreviewKind preview = parse_preview(a.preview);
  std::vector<std::string> outputs = preview_paths(a.output, preview);
  outputs.insert(outputs.begin(), a.output);
  const LayeredInputs in = load_layered_inputs(a.cascades, a.view, a.cascade_blend, outputs);
  const io::LayeredMaps& layered = in.layered;
  const ViewReceivers& view = in.view;
  const double load_ms = ms_since(t0);

  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  const auto t_run = Clock::now();
  const LayeredResult r = filter_layered(runtime, a.options, layered.set, layered.maps, view);
  const double run_ms = ms_since(t_run);

  const auto t_write = Clock::now();
  // The visibility and its previews appear together or not at all.
  HostImage shaded;
  io::write_images(output_with_previews(a.output, r.visibility, preview, view.x, view.ndl, &shaded));
  const double write_ms = ms_since(t_write);

  if (!a.quiet) {
    std::string layers;
    for (size_t k = 0; k < r.per_layer.size(); ++k) layers += (k ? " " : "") + std::to_string(r.per_layer[k]);
    std::string stages;
    auto stage = [&stages](const char* name, double seconds) {
      char b[48];
      std::snprintf(b, sizeof b, ", %s %.3f", name, seconds * 1e3);
      stages += b;
    };
    const StageTimes& s = r.times;
    if (s.pyramid > 0) stage("mips", s.pyramid);
    if (s.sat > 0) stage("sat", s.sat);
    if (s.zmax > 0) stage("zmax", s.zmax);
    if (s.classify > 0) stage("classify", s.classify);
    std::cout << formatted(
        "shadowfilter: %s | %zu layers of %dx%d, blend %.3g, receivers %dx%d (per layer %s; %zu blended, %zu "
        "background, %zu outside, %zu facing away) | device %s | device ms: transform %.3f, blur %.3f%s, project "
        "%.3f, reconstruct %.3f, blend %.3f, upload %.3f, download %.3f | wall ms: load %.1f, run %.1f, write "
        "%.1f, total %.1f | %s\n",
        (method_summary(a.options) + ", " + prefilter_summary(a.options)).c_str(), layered.set.layers.size(),
        layered.set.width, layered.set.height, layered.set.blend, view.width, view.height, layers.c_str(), r.blended,
        r.background, r.outside, r.facing_away, runtime->info().device_name.c_str(), s.transform * 1e3, s.blur * 1e3,
        stages.c_str(), r.times.project * 1e3, s.reconstruct * 1e3, r.times.blend * 1e3, r.times.upload * 1e3,
        r.times.download * 1e3, load_ms, run_ms, write_ms, ms_since(t0), a.output.c_str());
  }
  return 0;
}

}  // namespace sf::cli

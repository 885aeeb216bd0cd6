// `soft --cascades DIR|LIST --view VIEW -o OUT`: a soft method per layer of a cascade set under one
// area light (shadowfilter/layered.hpp, layer_soft_light), reconstructed at a camera view's
// receivers. The light keeps its world size and plane in every layer; its sides and plane come
// from the command line or layer 0's header (layered_light_from_header).
#include <chrono>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "image_io.hpp"
#include "json_summary.hpp"
#include "layered_inputs.hpp"
#include "options_soft.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"

namespace sf::cli {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// What a layered soft run cannot take: one light's map and receivers, lists, the batch, --auto
// (it measures one map), the single map's light (each layer's header holds its matrix) and depth
// encodings (layer files hold linear depth, cascade_io.hpp).
void refuse_single_map_options(const SoftArgs& a) {
  const auto refuse = refuse_with_cascades;
  if (a.cascades.empty()) throw InputError("--view, --cascade-blend and --light-plane need --cascades DIR|LIST");
  refuse(!a.shadow_map.empty(), "--shadow-map");
  refuse(!a.receivers.empty(), "--receivers");
  refuse(!a.receiver_depth.empty(), "--receiver-depth");
  refuse(!a.lights.empty(), "--lights");
  refuse(!a.frames.empty(), "--frames");
  refuse(a.keep_going, "--keep-going");
  refuse(!a.shard.empty(), "--shard");
  refuse(a.auto_args.enabled || !a.reference.empty(), "--auto or --reference");
  refuse(!a.light_type.empty() || std::isfinite(a.light_near) || std::isfinite(a.light_far) ||
             std::isfinite(a.light_fov) || std::isfinite(a.light_extent),
         "--light-type, --light-near, --light-far, --light-fov or --light-extent (the layers hold their matrices)");
  const DepthInputArgs& in = a.inputs;
  refuse(
      !in.encoding.empty() || !in.receiver_encoding.empty() || !std::isnan(in.near_plane) || !std::isnan(in.far_plane),
      "--encoding, --receiver-encoding, --near or --far (layer files hold linear depth)");
  refuse(!in.light.empty() || !in.camera.empty() || !in.camera_depth.empty() || !in.normals.empty(),
         "--light, --camera, --camera-depth or --normals (the view file holds the receivers)");
  if (a.view.empty()) throw InputError("--cascades needs --view VIEW (the camera view's receivers)");
  if (a.output.empty()) throw InputError("give -o/--output");
}

// The soft model has no receiver before the light (SoftLight::light_distance: such receivers read
// as outside it, a clamp): a --light-plane beyond some of the view's points is refused. Layers
// may start before the light (a stabilised layer's box reaches past the scene), receivers may not.
void refuse_receivers_before_the_light(const LayeredInputs& in, double plane) {
  const auto& m = in.layered.set.layers.front().transform.m;
  const double sd = std::sqrt(m[8] * m[8] + m[9] * m[9] + m[10] * m[10]);
  const ViewReceivers& v = in.view;
  size_t before = 0;
  double nearest = INFINITY;
  for (size_t i = 0; i < v.count(); ++i) {
    if (!std::isfinite(v.x[i]) || !std::isfinite(v.depth[i])) continue;
    const double depth = (m[8] * v.x[i] + m[9] * v.y[i] + m[10] * v.z[i]) / sd;  // along the light's axis
    nearest = std::min(nearest, depth);
    before += depth < plane;
  }
  if (before)
    throw InputError(
        formatted("%zu of the view's receivers lie before the light's plane at depth %.9g (the nearest at "
                  "%.9g along the light's axis): give a --light-plane before them",
                  before, plane, nearest));
}

}  // namespace

int run_soft_layered(const SoftArgs& a) {
  const auto t0 = Clock::now();
  refuse_single_map_options(a);
  SoftOptions options = soft_options(a);
  const LayeredInputs in = load_layered_inputs(a.cascades, a.view, a.cascade_blend, {a.output});
  const LayeredLight light = layered_light_from_header(in.files.front(), a);
  options.light.size = light.size;
  options.light.height = light.height;
  refuse_receivers_before_the_light(in, light.plane);
  const double load_ms = ms_since(t0);

  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  const auto t_run = Clock::now();
  const LayeredResult r = filter_layered(runtime, options, in.layered.set, light.plane, in.layered.maps, in.view);
  const double run_ms = ms_since(t_run);
  io::write_image(a.output, r.visibility);
  if (a.quiet) return 0;
  const StageTimes& s = r.times;
  if (a.json) {
    nlohmann::json j;
    j["command"] = "soft";
    j["method"] = soft_method_name(options.method);
    j["light"] = {{"size", options.light.size}, {"height", light_height(options.light)}, {"plane", light.plane}};
    j["layers"] = in.layered.set.layers.size();
    j["per_layer"] = r.per_layer;
    j["receivers"] = {{"width", in.view.width},     {"height", in.view.height}, {"blended", r.blended},
                      {"background", r.background}, {"outside", r.outside},     {"facing_away", r.facing_away}};
    j["device"] = runtime->info().device_name;
    j["device_ms"] = {{"transform", s.transform * 1e3},
                      {"mips", s.pyramid * 1e3},
                      {"sat", s.sat * 1e3},
                      {"project", s.project * 1e3},
                      {"reconstruct", s.reconstruct * 1e3},
                      {"blend", s.blend * 1e3}};
    j["wall_ms"] = {{"load", load_ms}, {"run", run_ms}, {"total", ms_since(t0)}};
    j["outputs"] = {a.output};
    print_json(j);
    return 0;
  }
  std::string layers;
  for (size_t k = 0; k < r.per_layer.size(); ++k) layers += (k ? " " : "") + std::to_string(r.per_layer[k]);
  std::cout << formatted(
      "shadowfilter soft: %s | %zu layers of %dx%d, blend %.3g, light %g x %g at depth %g | receivers %dx%d (per "
      "layer %s; %zu blended, %zu background, %zu outside, %zu facing away) | device %s | device ms: transform "
      "%.3f, mips %.3f, sat %.3f, project %.3f, reconstruct %.3f, blend %.3f | wall ms: load %.1f, run %.1f, total "
      "%.1f | %s\n",
      soft_method_name(options.method), in.layered.set.layers.size(), in.layered.set.width, in.layered.set.height,
      in.layered.set.blend, options.light.size, light_height(options.light), light.plane, in.view.width, in.view.height,
      layers.c_str(), r.blended, r.background, r.outside, r.facing_away, runtime->info().device_name.c_str(),
      s.transform * 1e3, s.pyramid * 1e3, s.sat * 1e3, s.project * 1e3, s.reconstruct * 1e3, s.blend * 1e3, load_ms,
      run_ms, ms_since(t0), a.output.c_str());
  return 0;
}

}  // namespace sf::cli

// `shadowfilter soft`: pcss, cssm, ssmm, ssmm-improved for one light or a list of lights.
#include "options_soft.hpp"

#include <OpenImageIO/imageio.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "camera_io.hpp"
#include "commands.hpp"
#include "filter_options.hpp"
#include "finite_numbers.hpp"
#include "help_format.hpp"
#include "image_io.hpp"
#include "image_bounds.hpp"
#include "io_detail.hpp"
#include "json_summary.hpp"
#include "light_list.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/view_projection.hpp"
#include "output_file.hpp"

namespace sf::cli {
namespace {

// A number of the map's header as stored: absent, or its text and its value (NaN when the text
// is not a whole finite number).
struct HeaderNumber {
  bool present = false;
  std::string text;
  double value = NAN;
};

HeaderNumber header_number(const OIIO::ImageSpec& spec, const char* name) {
  HeaderNumber h;
  const OIIO::ParamValue* p = spec.find_attribute(name);
  if (!p) return h;
  h.present = true;
  h.text = p->get_string();
  const size_t last = h.text.find_last_not_of(' ');
  const std::string number = last == std::string::npos ? "" : h.text.substr(0, last + 1);
  char* end = nullptr;
  const double v = std::strtod(number.c_str(), &end);
  if (!number.empty() && *end == '\0' && std::isfinite(v)) h.value = v;
  return h;
}

// The light's value: the command line's when given, else the header's; InputError naming the
// header's text when that is there but is not a finite number (nan is not "no attribute").
double light_value(double given, const HeaderNumber& header, const char* name, const char* option,
                   const std::string& path) {
  if (std::isfinite(given)) return given;
  if (header.present && !std::isfinite(header.value))
    throw InputError("shadow map '" + path + "': header " + name + "='" + io::detail::one_line(header.text) +
                     "' is not a finite number; give " + option);
  return header.value;
}

// The map's width in light units from "ortho_extents" ([x0, x1, y0, y1]): NaN when absent,
// InputError when present but not four finite numbers.
double header_extent(const OIIO::ImageSpec& spec, double given, const std::string& path) {
  if (std::isfinite(given)) return given;
  const OIIO::ParamValue* p = spec.find_attribute("ortho_extents");
  if (!p) return NAN;
  const std::string text = p->get_string();
  std::string spaced;
  for (char c : text) spaced += (c == '[' || c == ']' || c == ',') ? ' ' : c;
  std::istringstream in(spaced);
  std::vector<double> e;
  std::string item;
  while (in >> item) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    e.push_back(*end == '\0' && std::isfinite(v) ? v : NAN);
  }
  if (e.size() != 4 || !std::isfinite(e[0]) || !std::isfinite(e[1]) || !std::isfinite(e[2]) || !std::isfinite(e[3]))
    throw InputError("shadow map '" + path + "': header ortho_extents='" + io::detail::one_line(text) +
                     "' is not four finite numbers; give --light-extent");
  return e[1] - e[0];
}

// The area light's sides: --light-size when given, else the header's light_size, and its
// light_height where the light is not square (NaN size when the header has none).
void read_light_sides(const OIIO::ImageSpec& spec, const SoftArgs& a, const std::string& path, SoftLight& L) {
  if (!a.light_size.empty()) {
    L.size = a.light_size[0];
    if (a.light_size.size() == 2) L.height = a.light_size[1];
    return;
  }
  L.size = light_value(NAN, header_number(spec, "light_size"), "light_size", "--light-size", path);
  const HeaderNumber height = header_number(spec, "light_height");
  if (height.present) L.height = light_value(NAN, height, "light_height", "--light-size", path);
  // SoftLight reads a negative height as "square": a header's must be a side.
  if (height.present && !(L.height >= 0.0))
    throw InputError("shadow map '" + path + "': header light_height='" + io::detail::one_line(height.text) +
                     "' is not a side >= 0; give --light-size");
}

}  // namespace

// The light of a light file: orthographic (the map's width in light units from the projection's
// x scale) or perspective (its full field of view across the map's width), its planes, and the
// area light's size from --light-size.
SoftLight light_from_view(const io::ViewFile& file, const std::string& path, const SoftArgs& a) {
  if (!a.light_type.empty() || std::isfinite(a.light_near) || std::isfinite(a.light_far) ||
      std::isfinite(a.light_fov) || std::isfinite(a.light_extent))
    throw InputError("--light '" + path +
                     "' gives the light's type, planes and extent (its projection); drop --light-type, --light-near, "
                     "--light-far, --light-fov and --light-extent");
  if (a.light_size.empty())
    throw InputError("--light '" + path + "' has no area light size: give --light-size L or W,H (world units)");
  return soft_light(file.view_projection, a.light_size[0], a.light_size.size() == 2 ? a.light_size[1] : -1.0);
}

SoftLight light_from_header(const std::string& path, const SoftArgs& a) {
  SoftLight L;
  const auto in = io::detail::open_checked_image(path, "shadow map");
  const OIIO::ImageSpec& spec = in->spec();
  std::string type = spec.get_string_attribute("light_type");
  L.near_plane = light_value(a.light_near, header_number(spec, "near"), "near", "--light-near", path);
  L.far_plane = light_value(a.light_far, header_number(spec, "far"), "far", "--light-far", path);
  L.fov_degrees = light_value(a.light_fov, header_number(spec, "fov_degrees"), "fov_degrees", "--light-fov", path);
  read_light_sides(spec, a, path, L);
  L.extent = header_extent(spec, a.light_extent, path);
  in->close();
  if (!a.light_type.empty()) type = a.light_type;
  if (type == "orthographic") type = "ortho";
  if (type.empty()) type = "ortho";
  if (type != "ortho" && type != "perspective")
    throw InputError("--light-type must be ortho or perspective, got '" + type + "'");
  L.perspective = type == "perspective";
  if (!std::isfinite(L.size)) throw InputError("'" + path + "' has no light_size attribute: give --light-size");
  if (L.perspective) {
    if (!std::isfinite(L.near_plane) || !std::isfinite(L.far_plane) || !std::isfinite(L.fov_degrees))
      throw InputError(
          "a perspective light needs near, far and fov (header or --light-near, --light-far, --light-fov)");
  } else {
    if (!std::isfinite(L.extent))
      throw InputError(
          "an orthographic light needs the map's width in light units (header ortho_extents or --light-extent)");
    if (!std::isfinite(L.near_plane)) L.near_plane = 0.0;
    if (!std::isfinite(L.far_plane)) L.far_plane = 1.0;
  }
  return L;
}

LayeredLight layered_light_from_header(const std::string& path, const SoftArgs& a) {
  const auto in = io::detail::open_checked_image(path, "cascade layer");
  const OIIO::ImageSpec& spec = in->spec();
  SoftLight L;
  read_light_sides(spec, a, path, L);
  const HeaderNumber plane = header_number(spec, "light_plane");
  LayeredLight out;
  out.plane = light_value(a.light_plane, plane, "light_plane", "--light-plane", path);
  in->close();
  if (!std::isfinite(L.size)) throw InputError("'" + path + "' has no light_size attribute: give --light-size");
  if (!std::isfinite(out.plane))
    throw InputError("'" + path +
                     "' has no light_plane attribute: give --light-plane D (the world depth of the light's plane "
                     "along its axis)");
  out.size = L.size;
  out.height = L.height;
  return out;
}

CLI::App* add_soft_command(CLI::App& app, SoftArgs& a) {
  CLI::App* c = app.add_subcommand(
      "soft", "Soft shadows from square or rectangular area lights: pcss, cssm, ssmm, ssmm-improved (docs/soft.md)");
  c->add_option("--method", a.method, "pcss | cssm | ssmm | ssmm-improved")->capture_default_str();
  c->add_option("--shadow-map", a.shadow_map,
                "Depth map of one light (decoded as --encoding says; the light from its header or --light)");
  auto* rx = c->add_option("--receivers", a.receivers, "Receiver image u v d [f [ndl]] of that light");
  auto* rd = c->add_option("--receiver-depth", a.receiver_depth, "Planar receivers of the map's size");
  rx->excludes(rd);
  rd->excludes(rx);
  c->add_option("--lights", a.lights,
                "Light list file instead of --shadow-map: one light a line, 'SHADOWMAP RECEIVERS "
                "[weight=W] [size=L]' (paths relative to the file; # comments)");
  auto* out = c->add_option("-o,--output", a.output, "Visibility image");
  c->add_option("--frames", a.frames,
                "Batch: a list of frames, one a line: SHADOWMAP (RECEIVERS | depth=RECEIVER_DEPTH) OUTPUT "
                "(paths relative to the list, '#' comments; the light from each map's header)")
      ->excludes(out);
  c->add_flag("--keep-going", a.keep_going,
              "Batch: report a failed frame and carry on (the exit code is the number of failed frames)");
  c->add_option("--shard", a.shard,
                "Batch: run part K of N (frames K, K + N, K + 2N, ... of the list; 1 <= K <= N): N processes with "
                "K = 1..N write what one run writes")
      ->type_name("K/N");
  c->add_option("--cascades", a.cascades,
                "Layered maps instead of --shadow-map: a directory of cascade_K.exr or a comma-separated list "
                "(docs/cascades.md); the soft method runs per layer under one area light");
  c->add_option("--view", a.view, "With --cascades: the camera view's receivers (view.exr of `scene --layout`)");
  c->add_option("--cascade-blend", a.cascade_blend,
                "With --cascades: the blend band between layers, a fraction of each layer's depth range in "
                "[0, 1) (default: the headers')");
  c->add_option("--light-plane", a.light_plane,
                "With --cascades: the world depth of the area light's plane along the light's axis (default: "
                "layer 0's header light_plane)");
  add_light_size_option(c, a.light_size,
                        "Area light: L (a square) or W,H (W along the map's u axis, H along v), light-space units "
                        "(default: header light_size, light_height)");
  c->add_option("--light-type", a.light_type, "ortho | perspective (default: header light_type)");
  c->add_option("--light-near", a.light_near, "Perspective: near plane distance (default: header near)");
  c->add_option("--light-far", a.light_far, "Perspective: far plane distance (default: header far)");
  c->add_option("--light-fov", a.light_fov, "Perspective: full field of view, degrees (default: header fov_degrees)");
  c->add_option("--light-extent", a.light_extent,
                "Orthographic: map width in light units (default: header ortho_extents)");
  c->add_option("--soft-bias", a.options.bias, "Blocker test z < d_t - bias (d_t: the receiver's plane)")
      ->capture_default_str();
  add_receiver_plane_options(*c, a.options.receiver_plane, "pcss, ssmm");
  c->add_option("--normal-offset", a.options.normal_offset,
                "Texels each lookup moves along the receiver's normal (receivers with nx ny nz; 0: off) "
                "(default the method's: pcss, ssmm, ssmm-improved 0.5, cssm 0)");
  c->add_option("--soft-max-width", a.options.max_width, "Cap of kernel widths, texels")->capture_default_str();
  c->add_option("--cssm-order", a.options.cssm.order, "cssm: Fourier order M")->capture_default_str();
  c->add_option("--lookup", a.lookup, "cssm: mips | sat")->capture_default_str();
  c->add_option("--cssm-storage", a.cssm_storage,
                "cssm: the basis planes' storage, f32 | f16 | unorm16 (f16 and unorm16 with --lookup mips)")
      ->capture_default_str();
  c->add_option("--cssm-offset", a.options.cssm.offset, "cssm: d' = d - offset (< 0: 0.1 / M)")->capture_default_str();
  c->add_option("--cssm-scale", a.options.cssm.scale, "cssm: v = clamp(0.5 + scale (s - 0.5)) (< 0: 3)")
      ->capture_default_str();
  c->add_option("--cssm-normalise", a.options.cssm.normalise, "cssm: 1 = divide s by lit (the series at z = d)")
      ->capture_default_str();
  c->add_option("--cssm-sharpen", a.sharpen,
                "cssm: A,B of eq. 8.9 (p = 1 + A exp(-B (d - z_avg)); default 30,10M; A = 0: off)")
      ->delimiter(',')
      ->expected(2);
  c->add_option("--cssm-min-den", a.options.cssm.min_den, "cssm: 1 - s_f below this = no blocker")
      ->capture_default_str();
  c->add_option("--cssm-z-offset", a.options.cssm.z_offset,
                "cssm: offset of the z_avg stage (< 0: ~0.306 / M, where a lit texel reconstructs to 1)")
      ->capture_default_str();
  c->add_option("--cssm-width-scale", a.options.cssm.width_scale,
                "cssm: stage-2 kernel width multiplier (< 0: scale x lit)")
      ->capture_default_str();
  c->add_option("--cssm-contact", a.options.cssm.contact,
                "cssm: 1 = receivers without a stage-1 blocker still run stage 2 at their footprint")
      ->capture_default_str();
  c->add_option("--ssmm-n", a.options.ssmm.n, "ssmm: n x n texels per layer")->capture_default_str();
  add_soft_auto_options(*c, a);
  add_depth_options(*c, a.inputs);
  add_camera_options(*c, a.inputs);
  c->add_option("--device", a.device, "OpenCL device");
  c->add_flag("-q,--quiet", a.quiet, "Do not print the summary line");
  c->add_flag("--json", a.json, "Print the summary as one JSON object instead of a line of text");
  add_verbose_flag(*c, a.verbose);
  c->footer(std::string(kReceiverFormatHelp) + "\n\n" +
            "Examples:\n"
            "  shadowfilter soft --method pcss --shadow-map data/spheres/shadowmap.exr --receivers "
            "data/spheres/receivers.exr -o soft.exr\n"
            "  shadowfilter soft --method cssm --shadow-map spot_depth.exr --light spot.json --light-size 0.3 "
            "--camera camera.json --camera-depth camera_depth.exr -o soft.exr\n"
            "  shadowfilter soft --method ssmm --cascades city/ --view city/view.exr -o soft.exr\n"
            "  shadowfilter soft --auto --reference data/spheres/reference_soft.exr --shadow-map "
            "data/spheres/shadowmap.exr --receivers data/spheres/receivers.exr -o soft.exr\n"
            "docs/soft.md (methods), docs/inputs.md (your own depth buffers)");
  return c;
}

SoftLightInput load_soft_frame(const FrameFiles& files, const SoftArgs& a, std::vector<std::string>* warnings) {
  SoftLightInput li;
  li.light = files.light.empty() ? light_from_header(files.shadow_map, a)
                                 : light_from_view(io::load_view_file(files.light, "light"), files.light, a);
  FrameInputs in = load_frame(files, a.inputs);
  if (warnings) warnings->insert(warnings->end(), in.warnings.begin(), in.warnings.end());
  li.depth = std::move(in.depth);
  li.receivers = std::move(in.receivers);
  return li;
}

SoftLightInput load_soft_light(const std::string& shadow_map, const std::string& receivers,
                               const std::string& receiver_depth, const SoftArgs& overrides) {
  return load_soft_frame({shadow_map, receivers, receiver_depth, "", "", ""}, overrides);
}

SoftOptions soft_options(const SoftArgs& a) {
  SoftOptions opt = a.options;
  opt.method = find_soft_method(a.method);
  if (a.lookup == "mips")
    opt.cssm.lookup = Lookup::Mips;
  else if (a.lookup == "sat")
    opt.cssm.lookup = Lookup::Sat;
  else
    throw InputError("--lookup must be mips or sat, got '" + a.lookup + "'");
  try {
    opt.cssm.storage = parse_storage(a.cssm_storage);
  } catch (const InputError& e) {
    throw InputError(std::string("--cssm-storage: ") + e.what());
  }
  if (a.sharpen.size() == 2) {
    opt.cssm.sharpen_a = a.sharpen[0];
    opt.cssm.sharpen_b = a.sharpen[1];
  }
  return opt;
}

int run_soft(const SoftArgs& a) {
  if (!a.cascades.empty() || !a.view.empty() || !std::isnan(a.cascade_blend) || !std::isnan(a.light_plane))
    return run_soft_layered(a);
  if (a.auto_args.enabled && !a.frames.empty())
    throw InputError("--auto measures one input; run it on one frame and give the batch the options it chose");
  if (!a.frames.empty()) return run_soft_batch(a);
  if (!a.reference.empty() && !a.auto_args.enabled) throw InputError("--reference is the target of --auto");
  if (a.auto_args.enabled && a.reference.empty())
    throw InputError(
        "--auto needs --reference FILE: the exact soft visibility of these receivers (a ray-traced "
        "render, or a scene's reference_soft.exr)");
  if (a.auto_args.enabled && !a.lights.empty())
    throw InputError("--auto measures one light's map and receivers; it cannot take --lights");
  if (a.keep_going) throw InputError("--keep-going is for a batch (--frames)");
  if (!a.shard.empty()) throw InputError("--shard is for a batch (--frames)");
  const auto t0 = std::chrono::steady_clock::now();
  SoftOptions opt = soft_options(a);
  if (a.output.empty()) throw InputError("give -o/--output (or --frames LIST)");
  io::check_outputs({a.output}, {a.shadow_map, a.receivers, a.receiver_depth, a.lights, a.reference});
  std::vector<SoftLightInput> lights;
  std::vector<std::string> warnings;  // printed once the output is written
  if (!a.lights.empty()) {
    if (!a.shadow_map.empty() || !a.receivers.empty() || !a.receiver_depth.empty())
      throw InputError("--lights replaces --shadow-map and --receivers");
    if (!a.inputs.light.empty() || !a.inputs.camera.empty())
      throw InputError("--lights names each light's map and receivers; --light and --camera are for one light");
    for (const LightListEntry& entry : read_light_list(a.lights)) {
      SoftArgs over = a;
      if (std::isfinite(entry.size)) {
        over.light_size = {entry.size};
        if (entry.height >= 0.0) over.light_size.push_back(entry.height);
      }
      SoftLightInput li = load_soft_light(entry.shadow_map, entry.receivers, "", over);
      li.light.weight = entry.weight;
      lights.push_back(std::move(li));
    }
  } else {
    if (a.shadow_map.empty()) throw InputError("give --shadow-map (or --lights)");
    const FrameFiles files{a.shadow_map,    a.receivers,           a.receiver_depth,
                           a.inputs.camera, a.inputs.camera_depth, a.inputs.light};
    require_one_receiver_source(files);
    validate_depth_args(a.inputs);
    const std::vector<std::string> inputs{a.shadow_map,          a.receivers,    a.receiver_depth, a.inputs.camera,
                                          a.inputs.camera_depth, a.inputs.light, a.inputs.normals, a.reference};
    io::check_outputs({a.output}, inputs);
    lights.push_back(load_soft_frame(files, a, &warnings));
  }
  opt.light = lights.front().light;
  validate(opt);
  for (const auto& l : lights) {
    SoftOptions o = opt;
    o.light = l.light;
    validate(o);
  }
  auto rt = Runtime::create(a.device);
  apply_verbose(*rt, a.verbose);
  nlohmann::json chosen;
  if (a.auto_args.enabled) opt = choose_soft_auto_options(a, lights.front(), opt, rt, chosen);
  const auto t1 = std::chrono::steady_clock::now();
  const SoftResult r = soft_filter_lights(rt, opt, lights);
  const double run_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  io::write_image(a.output, r.visibility);
  print_warnings(warnings);
  if (!a.quiet && a.json) {
    nlohmann::json j;
    j["command"] = "soft";
    j["method"] = soft_method_name(opt.method);
    j["lights"] = lights.size();
    j["light"] = {{"size", opt.light.size},
                  {"height", light_height(opt.light)},
                  {"type", opt.light.perspective ? "perspective" : "ortho"}};
    j["receivers"] = {{"width", r.visibility.width}, {"height", r.visibility.height}, {"background", r.background}};
    j["device"] = rt->info().device_name;
    j["device_ms"] = {{"transform", r.times.transform * 1e3},
                      {"mips", r.times.pyramid * 1e3},
                      {"sat", r.times.sat * 1e3},
                      {"reconstruct", r.times.reconstruct * 1e3}};
    j["wall_ms"] = {
        {"run", run_ms},
        {"total", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()}};
    if (a.auto_args.enabled) j["auto"] = chosen;
    j["outputs"] = {a.output};
    j["warnings"] = warnings;
    print_json(j);
  } else if (!a.quiet)
    std::cout << formatted(
        "shadowfilter soft: %s, %zu light(s), light size %g x %g (%s) | receivers %dx%d (%zu background) | "
        "device ms: transform %.3f, mips %.3f, sat %.3f, reconstruct %.3f | wall ms: run %.1f, total %.1f | %s\n",
        soft_method_name(opt.method), lights.size(), opt.light.size, light_height(opt.light),
        opt.light.perspective ? "perspective" : "ortho", r.visibility.width, r.visibility.height, r.background,
        r.times.transform * 1e3, r.times.pyramid * 1e3, r.times.sat * 1e3, r.times.reconstruct * 1e3, run_ms,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(), a.output.c_str());
  return 0;
}

}  // namespace sf::cli

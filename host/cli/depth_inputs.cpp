// One frame's inputs, decoded as stated (depth_inputs.hpp, docs/inputs.md).
#include "depth_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "print.hpp"
#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/receiver_fit.hpp"

namespace sf::cli {
namespace {

std::string number(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

std::string percent(size_t part, size_t whole) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f%%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return b;
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// The finite depths of the map below 1 (1 = nothing hit): what its surfaces span.
void map_range(const HostImage& depth, double* lo, double* hi) {
  *lo = INFINITY, *hi = -INFINITY;
  for (float z : depth.data)
    if (std::isfinite(z) && z < 1.0f) *lo = std::min(*lo, double(z)), *hi = std::max(*hi, double(z));
}

// Makes the camera's receivers for the map in memory.
Receivers camera_frame_receivers(const FrameFiles& files, const DepthInputArgs& a, const HostImage& depth,
                                 std::vector<std::string>* warnings) {
  const io::ViewFile camera = io::load_view_file(files.camera, "camera");
  const io::ViewFile light = io::load_view_file(files.light, "light");
  const CameraDepth camera_depth =
      io::load_camera_depth(files.camera_depth, io::parse_camera_depth_kind(a.camera_depth_kind));
  if (camera.width && (camera.width != camera_depth.width || camera.height != camera_depth.height))
    throw InputError("camera '" + files.camera + "' says " + size_text(camera.width, camera.height) +
                     ", its depth buffer '" + files.camera_depth + "' is " +
                     size_text(camera_depth.width, camera_depth.height));
  if (light.width && (light.width != depth.width || light.height != depth.height))
    throw InputError("light '" + files.light + "' says " + size_text(light.width, light.height) + ", the map '" +
                     files.shadow_map + "' is " + size_text(depth.width, depth.height));
  CameraReceiverOptions options;
  options.map_width = depth.width;
  options.map_height = depth.height;
  if (!a.normals.empty()) options.normals = io::load_normal_image(a.normals, camera_depth.width, camera_depth.height);
  CameraReceiverCounts counts;
  Receivers rx;
  try {
    rx = camera_receivers(camera.view_projection, camera_depth, light.view_projection, options, &counts);
  } catch (const InputError& e) {
    throw InputError("camera depth '" + files.camera_depth + "': " + e.what());
  }
  const size_t surface = rx.count() - counts.background;
  if (warnings && surface >= 16 && counts.outside * 2 > surface)
    warnings->push_back(percent(counts.outside, surface) + " of the camera's surface points fall outside light '" +
                        files.light +
                        "' (u, v outside [0, 1], or beyond its planes): the light of this map and frame? Are its "
                        "matrices row-major? They come out lit");
  return rx;
}

}  // namespace

void add_depth_options(CLI::App& c, DepthInputArgs& a) {
  c.add_option("--encoding", a.encoding,
               "How the map stores depth: linear (d in [0, 1]; with --near/--far: world units along the light's "
               "axis) | perspective (window depth: OpenGL, D3D, Vulkan) | perspective-ndc (OpenGL NDC z in "
               "[-1, 1]) | reversed (reversed-Z) | reversed-infinite (reversed-Z, infinite far plane; --far = the "
               "depth that becomes d = 1) | reversed-linear (orthographic reversed-Z); default linear, or the "
               "light's with --light (docs/inputs.md)")
      ->type_name("NAME");
  c.add_option("--receiver-encoding", a.receiver_encoding,
               "How the receivers store d when not as the map: normalized (d in [0, 1], what `shadowfilter "
               "receivers` writes) or an --encoding name (with the map's planes); default the map's, or the "
               "receiver file's header")
      ->type_name("NAME");
  c.add_option("--near", a.near_plane, "The light's near plane, world units along its axis (no default)");
  c.add_option("--far", a.far_plane, "The light's far plane, world units along its axis (no default)");
  c.add_option("--beyond-far", a.beyond_far,
               "Depths past the far plane: error (default) | far (they mean nothing hit, e.g. Blender's 1e10)")
      ->type_name("error|far");
  c.add_option("--nonfinite", a.nonfinite, "Non-finite map texels: error (default) | far (nothing hit)")
      ->type_name("error|far");
  c.add_option("--light", a.light,
               "The light's JSON (view and projection, row-major; docs/inputs.md): the map's encoding and planes "
               "come from its projection");
}

void add_camera_options(CLI::App& c, DepthInputArgs& a) {
  c.add_option("--camera", a.camera,
               "The camera's JSON (view and projection): receivers made from its depth buffer (needs --camera-depth "
               "and --light)");
  c.add_option("--camera-depth", a.camera_depth, "The camera's depth buffer (row 0 = the picture's top row)");
  c.add_option("--camera-depth-kind", a.camera_depth_kind,
               "What the camera depth holds: window (the depth buffer) | view (distance along the camera's axis, "
               "world units: Blender's Z pass) | distance (along the ray from the eye) | position (world x y z)")
      ->type_name("window|view|distance|position");
  c.add_option("--normals", a.normals,
               "World-space normals of the camera's pixels (float, 3 channels); default: from the depth buffer");
}

void require_one_receiver_source(const FrameFiles& f) {
  const int sources = int(!f.receivers.empty()) + int(!f.receiver_depth.empty()) + int(!f.camera.empty());
  if (sources != 1)
    throw InputError("give exactly one of --receivers, --receiver-depth or --camera (receivers from a camera)");
  if (!f.camera.empty() && f.camera_depth.empty()) throw InputError("--camera needs --camera-depth DEPTH");
  if (f.camera.empty() && !f.camera_depth.empty()) throw InputError("--camera-depth needs --camera CAMERA.json");
  if (!f.camera.empty() && f.light.empty())
    throw InputError("--camera needs --light LIGHT.json (receivers are projected into the light's map)");
}

void validate_depth_args(const DepthInputArgs& a) {
  DepthEncoding e;
  if (!a.encoding.empty() && !parse_depth_encoding(a.encoding, &e))
    throw InputError("--encoding must be one of " + depth_encoding_names() + ", got '" + a.encoding + "'");
  if (!a.receiver_encoding.empty() && a.receiver_encoding != "normalized" &&
      !parse_depth_encoding(a.receiver_encoding, &e))
    throw InputError("--receiver-encoding must be normalized or one of " + depth_encoding_names() + ", got '" +
                     a.receiver_encoding + "'");
  if (a.beyond_far != "error" && a.beyond_far != "far")
    throw InputError("--beyond-far must be error or far, got '" + a.beyond_far + "'");
  if (a.nonfinite != "error" && a.nonfinite != "far")
    throw InputError("--nonfinite must be error or far, got '" + a.nonfinite + "'");
  (void)io::parse_camera_depth_kind(a.camera_depth_kind);
  if (!a.light.empty()) {
    if (!std::isnan(a.near_plane) || !std::isnan(a.far_plane))
      throw InputError(
          "--light gives the planes (its projection); drop --near/--far (an infinite far plane takes \"far\" in the "
          "light's file)");
    if (!a.encoding.empty() && a.encoding != "linear")
      throw InputError(
          "with --light the map is the light's window depth, or --encoding linear (world units along its "
          "axis); got --encoding " +
          a.encoding);
  }
  if (a.encoding == "reversed-linear" && (!std::isnan(a.near_plane) || !std::isnan(a.far_plane)))
    throw InputError("--encoding reversed-linear stores 1 - d; --near/--far do not apply to it");
}

io::DepthLoadOptions map_decoding(const DepthInputArgs& a, const std::optional<io::ViewFile>& light,
                                  const std::string& light_path) {
  validate_depth_args(a);
  io::DepthLoadOptions o;
  o.beyond_far_is_empty = a.beyond_far == "far";
  o.nonfinite = a.nonfinite == "far" ? io::NonFinitePolicy::Far : io::NonFinitePolicy::Error;
  if (light) {
    DepthDecoding d;
    try {
      d = window_depth_decoding(light->view_projection);
    } catch (const InputError& e) {
      throw InputError("light '" + light_path + "': " + e.what());
    }
    const ProjectionDepth pd = light_projection_depth(light->view_projection);
    if (a.encoding == "linear") {
      o.encoding = DepthEncoding::Linear;
      o.near_plane = pd.near_plane;
      o.far_plane = pd.far_plane;
      o.flag = "linear depth in world units along light '" + light_path + "''s axis, " + number(pd.near_plane) + ".." +
               number(pd.far_plane);
    } else {
      o.encoding = d.encoding;
      o.near_plane = d.near_plane;
      o.far_plane = d.far_plane;
      o.flag = std::string(depth_encoding_name(d.encoding)) + " window depth of light '" + light_path + "'";
      if (has_planes(d)) o.flag += " (near " + number(d.near_plane) + ", far " + number(d.far_plane) + ")";
    }
    return o;
  }
  if (!a.encoding.empty()) o.encoding = io::parse_depth_encoding(a.encoding);
  o.near_plane = a.near_plane;
  o.far_plane = a.far_plane;
  return o;
}

std::optional<io::DepthLoadOptions> stated_receiver_decoding(const DepthInputArgs& a, const io::DepthLoadOptions& map) {
  if (a.receiver_encoding.empty()) return std::nullopt;
  io::DepthLoadOptions o = map;
  o.flag = "--receiver-encoding";
  if (a.receiver_encoding == "normalized") {
    o.encoding = DepthEncoding::Linear;
    o.near_plane = o.far_plane = std::numeric_limits<double>::quiet_NaN();
    o.beyond_far_is_empty = false;
    o.flag = "--receiver-encoding normalized (d in [0, 1])";
    return o;
  }
  o.encoding = io::parse_depth_encoding(a.receiver_encoding);
  if (o.encoding == DepthEncoding::ReversedLinear)
    o.near_plane = o.far_plane = std::numeric_limits<double>::quiet_NaN();
  return o;
}

io::DepthLoadOptions frame_map_decoding(const FrameFiles& f, const DepthInputArgs& a) {
  std::optional<io::ViewFile> light;
  if (!f.light.empty()) light = io::load_view_file(f.light, "light");
  return map_decoding(a, light, f.light);
}

LoadedReceivers load_receivers_of(const FrameFiles& f, const DepthInputArgs& a, const HostImage& depth,
                                  const io::DepthLoadOptions& map) {
  require_one_receiver_source(f);
  LoadedReceivers out;
  if (!f.camera.empty())
    out.receivers = camera_frame_receivers(f, a, depth, &out.warnings);
  else
    out.receivers =
        io::load_receivers(f.receivers, f.receiver_depth, depth, map, stated_receiver_decoding(a, map), &out.header);
  return out;
}

FrameInputs load_frame(const FrameFiles& f, const DepthInputArgs& a) {
  require_one_receiver_source(f);
  const io::DepthLoadOptions map = frame_map_decoding(f, a);
  FrameInputs in;
  in.depth = io::load_depth_map(f.shadow_map, map);
  LoadedReceivers rx = load_receivers_of(f, a, in.depth, map);
  in.receivers = std::move(rx.receivers);
  in.warnings = std::move(rx.warnings);
  const std::vector<std::string> fit = fit_warnings(in.depth, in.receivers, rx.header, map);
  in.warnings.insert(in.warnings.end(), fit.begin(), fit.end());
  return in;
}

std::vector<std::string> fit_warnings(const HostImage& depth, const Receivers& rx, const io::ReceiverHeader& header,
                                      const io::DepthLoadOptions& map) {
  std::vector<std::string> w;
  const ReceiverFit fit = receiver_fit(depth, rx);
  const size_t placed = fit.inside + fit.outside;
  if (placed >= 16 && fit.outside * 2 > placed) {
    if (fit.u_max > 2.0 || fit.v_max > 2.0)
      w.push_back(percent(fit.outside, placed) + " of the receivers fall outside the map: u, v span [" +
                  number(fit.u_min) + ", " + number(fit.u_max) + "] x [" + number(fit.v_min) + ", " +
                  number(fit.v_max) +
                  "], texel indices? Receivers need u, v in [0, 1] (texel i's centre at (i + 0.5) / " +
                  std::to_string(depth.width) + "); outside the map they come out lit");
    else
      w.push_back(percent(fit.outside, placed) +
                  " of the receivers fall outside the map (u or v outside [0, 1]): receivers of another light or "
                  "frame? Outside the map they come out lit");
  }
  double z_lo, z_hi;
  map_range(depth, &z_lo, &z_hi);
  const std::string ranges = "receivers' d spans [" + number(fit.d_min) + ", " + number(fit.d_max) +
                             "], the map's surfaces [" + number(z_lo) + ", " + number(z_hi) + "]";
  // Nothing lies in front of the light's first surface in a real scene, and a scene in which
  // (nearly) every receiver is shadowed is rare: at 95% either way the depths were misread more
  // likely than not. (Made-up receivers, such as a plane floating over a map, stay below it.)
  if (fit.inside >= 64 && fit.in_front * 20 > fit.inside * 19)
    w.push_back(percent(fit.in_front, fit.inside) +
                " of the receivers lie in front of the map's first surface, which cannot be (" + ranges +
                "): their d is in another encoding than the map's? --receiver-encoding states theirs; they come out "
                "lit (docs/inputs.md)");
  if (fit.inside >= 64 && fit.behind * 20 > fit.inside * 19)
    w.push_back(percent(fit.behind, fit.inside) + " of the receivers lie behind the map's first surface (" + ranges +
                "): nearly all in shadow; their d in another encoding than the map's? --receiver-encoding states "
                "theirs (docs/inputs.md)");
  if (header.map_width > 0 && !rx.grid && (header.map_width != depth.width || header.map_height != depth.height))
    w.push_back("the receivers' footprints are in texels of a " + size_text(header.map_width, header.map_height) +
                " map (their header), this map is " + size_text(depth.width, depth.height) +
                ": make them for this map (`shadowfilter receivers --shadow-map MAP`)");
  const DepthDecoding d = map.decoding();
  if (has_planes(d) && std::isfinite(header.light_near) && std::isfinite(header.light_far)) {
    const double tolerance = 1e-6 * std::max(1.0, std::fabs(d.far_plane));
    if (std::fabs(header.light_near - d.near_plane) > tolerance ||
        std::fabs(header.light_far - d.far_plane) > tolerance)
      w.push_back("the receivers were made for a light with planes " + number(header.light_near) + ".." +
                  number(header.light_far) + " (their header), the map is decoded with " + number(d.near_plane) + ".." +
                  number(d.far_plane) + ": their d and the map's differ in scale");
  }
  return w;
}

void print_warnings(const std::vector<std::string>& warnings, const std::string& where) {
  for (const std::string& w : warnings)
    std::cerr << formatted("shadowfilter: warning: %s%s\n", where.empty() ? "" : (where + ": ").c_str(), w.c_str());
}

}  // namespace sf::cli

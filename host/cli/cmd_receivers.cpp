// `shadowfilter receivers`: receivers from a camera's depth buffer and a light (docs/inputs.md),
// written as u v d f ndl for `filter --receivers` and `soft --receivers`.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "camera_io.hpp"
#include "commands.hpp"
#include "output_file.hpp"
#include "help_format.hpp"
#include "json_summary.hpp"
#include "print.hpp"
#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

using Clock = std::chrono::steady_clock;

void parse_map_size(const std::string& text, int* w, int* h) {
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", w, h, &tail) != 2 || *w <= 0 || *h <= 0 || *w > (1 << 16) || *h > (1 << 16))
    throw InputError("--map-size must be WxH with 1..65536 texels a side, got '" + text + "'");
}

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

CLI::App* add_receivers_command(CLI::App& app, ReceiversArgs& a) {
  CLI::App* c = app.add_subcommand(
      "receivers", "Receivers (u v d f ndl) from a camera's depth buffer and a light, for filter and soft");
  c->add_option("--camera", a.inputs.camera, "The camera's JSON: view and projection, row-major (docs/inputs.md)")
      ->required();
  c->add_option("--camera-depth", a.inputs.camera_depth, "The camera's depth buffer (row 0 = the picture's top row)")
      ->required();
  c->add_option("--light", a.inputs.light, "The light's JSON: view and projection of its shadow map")->required();
  c->add_option("-o,--output", a.output, "Receiver image (.exr or .tif: float u v d f ndl)")->required();
  c->add_option("--camera-depth-kind", a.inputs.camera_depth_kind,
                "What the camera depth holds: window (the depth buffer) | view (distance along the camera's axis, "
                "world units: Blender's Z pass) | distance (along the ray from the eye) | position (world x y z)")
      ->type_name("window|view|distance|position");
  c->add_option("--normals", a.inputs.normals,
                "World-space normals of the camera's pixels (float, 3 channels); default: from the depth buffer");
  auto* map = c->add_option("--shadow-map", a.shadow_map, "The light's map: footprints in its texels (size only)");
  auto* size = c->add_option("--map-size", a.map_size, "The map's size WxH, instead of --shadow-map");
  map->excludes(size);
  size->excludes(map);
  c->add_option("--threads", a.threads, "Threads (default: every core)");
  c->add_flag("-q,--quiet", a.quiet, "Do not print the summary line");
  c->add_flag("--json", a.json, "Print the summary as one JSON object instead of a line of text");
  c->footer(
      std::string(
          "Writes per camera pixel: u, v (the surface point in the light's map, [0, 1], texel i's centre at "
          "(i + 0.5) / W), d = (z - near) / (far - near) along the light's axis, f = the pixel's footprint in "
          "the map's level-0 texels, ndl = n.l towards the light, nx ny nz = the normal in light space scaled "
          "to one texel (what --normal-offset moves along), dudx dvdx dudy dvdy = the Jacobian of (u W, v H) over "
          "the pixel (what --max-anisotropy follows); NaN on background pixels; u = v = -1 "
          "outside the light's frustum. Its header names the map size and the light's planes.\n\n") +
      "Examples:\n"
      "  shadowfilter receivers --camera camera.json --camera-depth camera_depth.exr --light sun.json "
      "--shadow-map sun_depth.exr -o rx.exr\n"
      "  shadowfilter receivers --camera camera.json --camera-depth Z.exr --camera-depth-kind view --light "
      "lamp.json --map-size 2048x2048 -o rx.exr\n"
      "docs/inputs.md: the JSON files, clip spaces (opengl, d3d, vulkan), reversed-Z, Blender");
  return c;
}

int run_receivers(const ReceiversArgs& a) {
  const auto t0 = Clock::now();
  if (a.shadow_map.empty() == a.map_size.empty())
    throw InputError("give --shadow-map MAP or --map-size WxH (footprints are in the map's texels)");
  const std::string ext = extension_of(a.output);
  if (ext != ".exr" && ext != ".tif" && ext != ".tiff")
    throw InputError("output image '" + a.output +
                     "': receivers are written as float .exr or .tif (12 channels), not '" + ext + "'");
  if (a.threads < 0) throw InputError("--threads must be >= 0, got " + std::to_string(a.threads));
  io::check_outputs({a.output},
                    {a.inputs.camera, a.inputs.camera_depth, a.inputs.light, a.inputs.normals, a.shadow_map});
  int map_w = 0, map_h = 0;
  if (!a.map_size.empty()) {
    parse_map_size(a.map_size, &map_w, &map_h);
  } else {
    io::image_size(a.shadow_map, "shadow map", &map_w, &map_h);
  }
  const io::ViewFile camera = io::load_view_file(a.inputs.camera, "camera");
  const io::ViewFile light = io::load_view_file(a.inputs.light, "light");
  const CameraDepth depth =
      io::load_camera_depth(a.inputs.camera_depth, io::parse_camera_depth_kind(a.inputs.camera_depth_kind));
  if (camera.width && (camera.width != depth.width || camera.height != depth.height))
    throw InputError("camera '" + a.inputs.camera + "' says " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + ", its depth buffer is " + std::to_string(depth.width) + "x" +
                     std::to_string(depth.height));
  if (light.width && (light.width != map_w || light.height != map_h))
    throw InputError("light '" + a.inputs.light + "' says " + std::to_string(light.width) + "x" +
                     std::to_string(light.height) + ", the map is " + std::to_string(map_w) + "x" +
                     std::to_string(map_h));
  CameraReceiverOptions options;
  options.map_width = map_w;
  options.map_height = map_h;
  options.threads = a.threads;
  if (!a.inputs.normals.empty()) options.normals = io::load_normal_image(a.inputs.normals, depth.width, depth.height);
  const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();

  const auto t_run = Clock::now();
  CameraReceiverCounts counts;
  Receivers rx;
  try {
    rx = camera_receivers(camera.view_projection, depth, light.view_projection, options, &counts);
  } catch (const InputError& e) {
    throw InputError("camera depth '" + a.inputs.camera_depth + "': " + e.what());
  }
  const double run_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_run).count();

  const ProjectionDepth light_depth = light_projection_depth(light.view_projection);
  HostImage image(rx.width, rx.height, 12);
  image.channel_names = {"u", "v", "d", "f", "ndl", "nx", "ny", "nz", "dudx", "dvdx", "dudy", "dvdy"};
  for (size_t i = 0; i < rx.count(); ++i) {
    float* p = &image.data[i * 12];
    p[0] = rx.u[i], p[1] = rx.v[i], p[2] = rx.d[i], p[3] = rx.f[i], p[4] = rx.ndl[i];
    p[5] = rx.nx[i], p[6] = rx.ny[i], p[7] = rx.nz[i];
    p[8] = rx.dudx[i], p[9] = rx.dvdx[i], p[10] = rx.dudy[i], p[11] = rx.dvdy[i];
  }
  image.attributes = io::receiver_header_attributes(map_w, map_h, light_depth.near_plane, light_depth.far_plane);
  const auto t_write = Clock::now();
  io::write_image(a.output, image);
  const double write_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_write).count();

  const size_t surface = rx.count() - counts.background;
  std::vector<std::string> warnings;
  if (surface >= 16 && counts.outside * 2 > surface) {
    char b[96];
    std::snprintf(b, sizeof b, "%.0f%% of the camera's surface points fall outside the light",
                  100.0 * double(counts.outside) / double(surface));
    warnings.push_back(std::string(b) +
                       " (u, v outside [0, 1], or beyond its planes): the light of this camera's frame? Are the "
                       "matrices row-major? They come out lit");
  }
  print_warnings(warnings);
  const int threads = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  if (a.quiet) return 0;
  if (a.json) {
    nlohmann::json j;
    j["command"] = "receivers";
    j["camera"] = {{"width", rx.width}, {"height", rx.height}};
    j["map"] = {{"width", map_w}, {"height", map_h}};
    j["light"] = {{"perspective", light_depth.perspective},
                  {"reversed_z", light_depth.reversed},
                  {"near", light_depth.near_plane},
                  {"far", light_depth.far_plane}};
    j["counts"] = {{"background", counts.background}, {"outside", counts.outside}, {"no_normal", counts.no_normal}};
    j["threads"] = threads;
    j["wall_ms"] = {{"load", load_ms}, {"run", run_ms}, {"write", write_ms}};
    j["outputs"] = {a.output};
    j["warnings"] = warnings;
    print_json(j);
    return 0;
  }
  std::cout << formatted(
      "shadowfilter receivers: %dx%d camera pixels (%zu background, %zu outside the light, %zu without a normal) | "
      "map %dx%d, %s light, planes %g..%g | wall ms: load %.1f, receivers %.1f (%d threads), write %.1f | %s\n",
      rx.width, rx.height, counts.background, counts.outside, counts.no_normal, map_w, map_h,
      light_depth.perspective ? "perspective" : "orthographic", light_depth.near_plane, light_depth.far_plane, load_ms,
      run_ms, threads, write_ms, a.output.c_str());
  return 0;
}

}  // namespace sf::cli

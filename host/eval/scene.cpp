// Scenes for evaluate: the generator's directories (docs/scenes.md) or images in memory, with
// the receivers that the map can shadow.
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "evaluate.hpp"
#include "image_bounds.hpp"
#include "image_io.hpp"
#include "io_detail.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {
namespace fs = std::filesystem;

namespace {

// First channel of a camera-view reference image (half EXR), or an empty image when there is
// none; read as every input image is (a regular file within the memory budget, io_detail.hpp).
HostImage load_reference(const std::string& path) {
  HostImage img;
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) return img;
  const io::detail::RawImage raw = io::detail::read_raw(path, "reference image");
  img = HostImage(raw.width, raw.height, 1);
  for (size_t i = 0; i < img.texels(); ++i) img.data[i] = raw.at(i, 0);
  return img;
}

// The area light of a shadow map's header (Scene::light), or InputError saying why there is none
// (evaluate never guesses a light).
SoftLight header_light(const std::string& path) {
  const auto in = io::detail::open_checked_image(path, "shadow map");
  const OIIO::ImageSpec& spec = in->spec();
  auto number = [&](const char* name) {
    const OIIO::ParamValue* p = spec.find_attribute(name);
    if (!p) throw InputError("shadow map '" + path + "': its light_size needs a header " + name);
    const std::string text = p->get_string();
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(v))
      throw InputError("shadow map '" + path + "': header " + name + "='" + io::detail::one_line(text) +
                       "' is not a finite number");
    return v;
  };
  if (!spec.find_attribute("light_size"))
    throw InputError("the scene's shadow map names no area light (header light_size)");
  SoftLight L;
  L.size = number("light_size");
  if (spec.find_attribute("light_height")) {
    L.height = number("light_height");
    // SoftLight reads a negative height as "square": a header's must be a side.
    if (!(L.height >= 0.0)) throw InputError("shadow map '" + path + "': header light_height is not a side >= 0");
  }
  // As `soft` reads it: orthographic (also "ortho", and when absent) or perspective.
  const std::string type = spec.get_string_attribute("light_type");
  if (!type.empty() && type != "orthographic" && type != "ortho" && type != "perspective")
    throw InputError("shadow map '" + path + "': header light_type='" + io::detail::one_line(type) +
                     "' is neither orthographic nor perspective");
  L.perspective = type == "perspective";
  L.near_plane = number("near");
  L.far_plane = number("far");
  if (L.perspective) {
    L.fov_degrees = number("fov_degrees");
  } else {
    std::string e = spec.get_string_attribute("ortho_extents");
    for (char& c : e)
      if (c == '[' || c == ']' || c == ',') c = ' ';
    std::istringstream es(e);
    double x0 = NAN, x1 = NAN;
    if (!(es >> x0 >> x1) || !std::isfinite(x1 - x0))
      throw InputError("shadow map '" + path + "': its light_size needs a header ortho_extents [x0, x1, y0, y1]");
    L.extent = x1 - x0;
  }
  return L;
}

void analyse(Scene& s) {
  const Receivers& rx = s.receivers;
  s.valid.assign(rx.count(), 0);
  s.valid_count = 0;
  s.traced.assign(rx.count(), 0);
  s.traced_count = 0;
  s.max_footprint = 1.0;
  for (size_t i = 0; i < rx.count(); ++i) {
    if (!std::isfinite(rx.d[i])) continue;
    if (!rx.grid && !(rx.u[i] >= 0.0f && rx.u[i] <= 1.0f && rx.v[i] >= 0.0f && rx.v[i] <= 1.0f)) continue;
    s.valid[i] = 1;
    ++s.valid_count;
    if (!(rx.has_ndl && rx.ndl[i] <= 0.0f)) {  // NaN ndl: unknown, counted
      s.traced[i] = 1;
      ++s.traced_count;
    }
    if (!rx.grid && rx.has_footprint && std::isfinite(rx.f[i]))
      s.max_footprint = std::max(s.max_footprint, double(rx.f[i]));
  }
}

}  // namespace

HostImage load_soft_reference(const std::string& path) {
  const io::detail::RawImage raw = io::detail::read_raw(path, "soft reference");
  if (raw.channels != 1)
    throw InputError("soft reference '" + path + "' has " + std::to_string(raw.channels) +
                     " channels; give a one-channel visibility image");
  HostImage img(raw.width, raw.height, 1);
  img.data = raw.pixels;
  return img;
}

Scene make_scene(std::string name, HostImage depth, Receivers receivers) {
  Scene s;
  s.name = std::move(name);
  s.depth = std::move(depth);
  s.receivers = std::move(receivers);
  analyse(s);
  return s;
}

Scene load_scene(const std::string& dir) {
  const fs::path p(dir);
  if (!fs::is_directory(p)) throw InputError("scene directory '" + dir + "' does not exist");
  for (const char* f : {"shadowmap.exr", "receivers.exr"})
    if (!fs::exists(p / f)) throw InputError("scene directory '" + dir + "' has no " + f);
  Scene s = make_scene(fs::absolute(p).lexically_normal().filename().string(),
                       io::load_depth_map((p / "shadowmap.exr").string(), {}),
                       io::load_receiver_image((p / "receivers.exr").string()));
  if (s.name.empty()) s.name = fs::absolute(p).lexically_normal().parent_path().filename().string();
  s.dir = dir;
  try {
    s.light = header_light((p / "shadowmap.exr").string());
  } catch (const InputError& e) {
    s.no_light = e.what();
  }
  s.ref_hard = load_reference((p / "reference_hard.exr").string());
  s.ref_soft = load_reference((p / "reference_soft.exr").string());
  for (const HostImage* r : {&s.ref_hard, &s.ref_soft})
    if (r->width && (r->width != s.receivers.width || r->height != s.receivers.height))
      throw InputError("scene '" + dir + "': reference size differs from the receivers'");
  return s;
}

}  // namespace sf::eval

// Scenes for evaluate: the generator's directories (docs/scenes.md) or images in memory, with
// the receivers that the map can shadow.
#include <cmath>
#include <filesystem>

#include "evaluate.hpp"
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
  s.ref_hard = load_reference((p / "reference_hard.exr").string());
  s.ref_soft = load_reference((p / "reference_soft.exr").string());
  for (const HostImage* r : {&s.ref_hard, &s.ref_soft})
    if (r->width && (r->width != s.receivers.width || r->height != s.receivers.height))
      throw InputError("scene '" + dir + "': reference size differs from the receivers'");
  return s;
}

}  // namespace sf::eval

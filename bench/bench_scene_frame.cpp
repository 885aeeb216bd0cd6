// Built-in scenes as benchmark frames (bench_common.hpp scene_frame): the light's depth map and
// the camera's receivers of the scene library, one render per (scene, map, screen).
#include <map>
#include <tuple>

#include "bench_common.hpp"
#include "scene_generate.hpp"
#include "scene_render.hpp"

namespace sf::bench {

const EsmFrame& scene_frame(const std::string& scene, int map, int width, int height) {
  static std::map<std::tuple<std::string, int, int, int>, EsmFrame> frames;
  const auto key = std::make_tuple(scene, map, width, height);
  if (const auto it = frames.find(key); it != frames.end()) return it->second;
  scene::SceneRequest req;
  req.scene = scene;
  req.out_dir = "unused";  // make_setup writes nothing
  req.map_size = map;
  req.receivers = std::to_string(width) + "x" + std::to_string(height);
  req.samples = 1;
  req.progress = false;
  const scene::SceneSetup setup = scene::make_setup(req);
  const scene::SceneRenderer renderer(setup);
  EsmFrame& fr = frames[key];
  fr.depth = renderer.shadow_map().data;
  const HostImage rx = renderer.camera_view(false).receivers;  // u v d f ndl
  const size_t count = size_t(rx.width) * rx.height;
  fr.u.resize(count), fr.v.resize(count), fr.d.resize(count), fr.f.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const float* p = &rx.data[i * rx.channels];
    fr.u[i] = p[0], fr.v[i] = p[1], fr.d[i] = p[2], fr.f[i] = p[3];
  }
  return fr;
}

}  // namespace sf::bench

// The time of camera_receivers() at 1920x1080 (docs/inputs.md; sf_measure, not part of the test
// suite):
//   sf_measure --gtest_filter='ReceiversTime.*'  [SF_RECEIVERS_DIR=DIR: also write the scene's
//   files there for timing `shadowfilter receivers` itself]
// The analytic scene of the input tests seen by a 1920x1080 OpenGL camera, a 2048x2048 spot
// light's map; the median of 7 runs on 1 thread and on every core.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <thread>

#include "analytic_setups.hpp"
#include "image_io.hpp"
#include "shadowfilter/camera_receivers.hpp"

namespace sf::test {
namespace {

using namespace analytic;

void time_receivers(const char* name, View camera) {
  const Scene scene;
  camera.width = 1920, camera.height = 1080;
  camera.tan_half_x = camera.tan_half_y * 1920.0 / 1080.0;
  View light = spot_light(ClipSpace::OpenGL, Depth::Conventional);
  light.width = light.height = 2048;
  const CameraTruth truth = render_camera(scene, camera);
  size_t background = 0;
  for (int s : truth.surface) background += s < 0;
  CameraDepth depth;
  depth.width = camera.width, depth.height = camera.height, depth.values = truth.window;
  const char* dir = std::getenv("SF_RECEIVERS_DIR");
  if (dir && background > 0) {
    HostImage d(camera.width, camera.height, 1);
    d.data = truth.window;
    io::write_image(std::string(dir) + "/camera_depth.exr", d);
    std::ofstream(std::string(dir) + "/camera.json") << view_file(camera);
    std::ofstream(std::string(dir) + "/light.json") << view_file(light);
  }
  for (int threads : {1, int(std::max(1u, std::thread::hardware_concurrency()))}) {
    CameraReceiverOptions opt;
    opt.map_width = opt.map_height = 2048;
    opt.threads = threads;
    std::vector<double> ms;
    for (int run = 0; run < 7; ++run) {
      const auto t0 = std::chrono::steady_clock::now();
      const Receivers rx = camera_receivers(camera.matrices(), depth, light.matrices(), opt);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      ASSERT_EQ(rx.count(), size_t(1920) * 1080);
    }
    std::sort(ms.begin(), ms.end());
    std::printf("camera_receivers 1920x1080 %s (%.0f%% background), %d thread%s: median %.1f ms (min %.1f, max %.1f)\n",
                name, 100.0 * double(background) / double(truth.surface.size()), threads, threads == 1 ? "" : "s",
                ms[3], ms[0], ms[6]);
  }
}

TEST(ReceiversTime, FullHdCamera) {
  time_receivers("the input tests' view", camera_view(ClipSpace::OpenGL, Depth::Conventional));
  View down = camera_view(ClipSpace::OpenGL, Depth::Conventional);
  down = look_at({0.3, 3.0, 0.2}, {0.0, 0.0, -0.2}, {0, 0, -1}, Kind::Perspective, ClipSpace::OpenGL,
                 Depth::Conventional, 0, 0);
  down.tan_half_y = std::tan(0.5 * 52.0 * M_PI / 180.0);
  down.near_plane = 0.5, down.far_plane = 30.0;
  time_receivers("looking down at the floor and the objects", down);
}

}  // namespace
}  // namespace sf::test

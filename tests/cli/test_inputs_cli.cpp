// Your own depth buffers through the command (docs/inputs.md): `receivers` then `filter`, the
// one-shot `filter --camera`, a frame list and `soft` on the analytic scene against its ray-cast
// truth; every inconsistent input an error (exit 2, one line, nothing written)
// or a warning; help, --version and --json.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "analytic_setups.hpp"
#include "cli_runner.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/camera_receivers.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;
using namespace analytic;

class InputsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("inputs_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void write_text(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }

  // The scene as a renderer hands it over: a spot light's window depth (OpenGL) and a D3D
  // camera's depth buffer, with their JSON files.
  void write_scene() {
    io::write_image(path("map.exr"), render_map(scene_, light_, Store::Window));
    truth_ = render_camera(scene_, camera_);
    HostImage depth(camera_.width, camera_.height, 1);
    depth.data = truth_.window;
    io::write_image(path("camera_depth.exr"), depth);
    write_text("camera.json", view_file(camera_));
    write_text("light.json", view_file(light_));
  }
  std::string camera_args() const {
    return " --light " + path("light.json") + " --camera " + path("camera.json") + " --camera-depth " +
           path("camera_depth.exr");
  }
  Mismatches against_truth(const std::string& file) const {
    return compare_with_truth(scene_, light_, truth_, io::load_depth_map(path(file), {}).data);
  }

  // exit 2, one line containing `expect`, no output written.
  void expect_input_error(const std::string& args, const std::string& expect) {
    const RunResult r = run_cli(args + " -o " + path("out.exr"), dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(path("out.exr")));
  }

  Scene scene_;
  View camera_ = camera_view(ClipSpace::D3D, Depth::Conventional);
  View light_ = spot_light(ClipSpace::OpenGL, Depth::Conventional);
  CameraTruth truth_;
  std::string dir_;
};

// receivers, then filter with them; the one-shot filter --camera gives the same bytes, so does a
// frame list; soft takes the camera too. Every result is within 0.5% of the ray-cast truth away
// from shadow edges.
TEST_F(InputsCli, CameraReceiversThroughEveryRouteMatchTheRayCastTruth) {
  write_scene();
  RunResult r =
      run_cli("receivers" + camera_args() + " --shadow-map " + path("map.exr") + " -o " + path("rx.exr"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(count_lines(r.out), 1u) << r.out;
  EXPECT_NE(r.out.find("160x120 camera pixels"), std::string::npos) << r.out;
  // The file holds what the library computes, with the header filter reads.
  CameraDepth depth;
  depth.width = camera_.width, depth.height = camera_.height, depth.values = truth_.window;
  CameraReceiverOptions opt;
  opt.map_width = opt.map_height = kMapSize;
  const Receivers expected = camera_receivers(camera_.matrices(), depth, light_.matrices(), opt);
  io::ReceiverHeader header;
  const Receivers written = io::load_receiver_image(path("rx.exr"), {}, std::nullopt, &header);
  EXPECT_TRUE(header.normalized);
  EXPECT_EQ(header.map_width, kMapSize);
  EXPECT_NEAR(header.light_near, light_.near_plane, 1e-9);
  ASSERT_EQ(written.count(), expected.count());
  for (size_t i = 0; i < expected.count(); ++i) {
    if (std::isnan(expected.d[i])) {
      EXPECT_TRUE(std::isnan(written.d[i]));
      continue;
    }
    ASSERT_EQ(written.u[i], expected.u[i]);
    ASSERT_EQ(written.d[i], expected.d[i]);
    ASSERT_EQ(written.f[i], expected.f[i]);
  }

  r = run_cli("filter --shadow-map " + path("map.exr") + " --light " + path("light.json") + " --receivers " +
                  path("rx.exr") + " --method sm -o " + path("vis.exr"),
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const Mismatches two_step = against_truth("vis.exr");
  EXPECT_GT(two_step.compared, 8000u);
  EXPECT_LE(two_step.fraction(), 0.005) << two_step.mismatched << " of " << two_step.compared;

  r = run_cli("filter --shadow-map " + path("map.exr") + camera_args() + " --method sm --preview shaded --json -o " +
                  path("one_shot.exr"),
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["command"], "filter");
  EXPECT_EQ(summary["filter"]["method"], "sm");
  EXPECT_EQ(summary["receivers"]["width"], camera_.width);
  EXPECT_EQ(summary["outputs"].size(), 3u);
  EXPECT_EQ(io::load_depth_map(path("one_shot.exr"), {}).data, io::load_depth_map(path("vis.exr"), {}).data);
  EXPECT_TRUE(fs::exists(path("one_shot.png")));
  EXPECT_TRUE(fs::exists(path("one_shot_shaded.png")));

  write_text("frames.txt", "map.exr camera=camera.json camera-depth=camera_depth.exr light=light.json framed.exr\n");
  r = run_cli("filter --frames " + path("frames.txt") + " --method sm -q", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(io::load_depth_map(path("framed.exr"), {}).data, io::load_depth_map(path("vis.exr"), {}).data);

  // pcss with a small light: its penumbrae are a texel or two wide where the occluders stand
  // close to their shadows.
  r = run_cli("soft --method pcss --shadow-map " + path("map.exr") + camera_args() + " --light-size 0.05 -q -o " +
                  path("soft.exr"),
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Mismatches soft = against_truth("soft.exr");
  EXPECT_LE(soft.fraction(), 0.01) << soft.mismatched << " of " << soft.compared;
}

// Each inconsistent input, row by row: an error or a warning, never silence.
TEST_F(InputsCli, SilentCasesOfTheIssueAreNoLongerSilent) {
  // A float map in world units (4-16 m) read as linear [0, 1]: refused with the range and the fix.
  HostImage world(32, 32, 1, 12.0f);
  for (int y = 8; y < 16; ++y)
    for (int x = 8; x < 16; ++x) world.at(x, y) = 6.0f;
  world.at(0, 0) = 4.0f, world.at(31, 31) = 16.0f;
  io::write_image(path("world.exr"), world);
  io::write_image(path("ground.exr"), HostImage(32, 32, 1, 12.0f));
  const std::string planar = "filter --shadow-map " + path("world.exr") + " --receiver-depth " + path("ground.exr");
  expect_input_error(planar, "depths span [4, 16], outside [0, 1] of --encoding linear");
  expect_input_error(planar, "--encoding linear --near N --far F");
  // ... and with --near 4 --far 16 it is world units: the block shadows the ground below it.
  RunResult r = run_cli(planar + " --near 4 --far 16 --method sm -q -o " + path("world_vis.exr"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const HostImage vis = io::load_depth_map(path("world_vis.exr"), {});
  EXPECT_EQ(vis.at(11, 11), 0.0f);
  EXPECT_EQ(vis.at(24, 24), 1.0f);

  // --encoding perspective without --near/--far: no silent defaults.
  expect_input_error(planar + " --encoding perspective", "needs both --near and --far");

  // An 8-bit PNG depth map: refused with the reason.
  HostImage gray(32, 32, 1, 0.5f);
  const std::string png8 = path("depth8.png");
  {
    auto out = OIIO::ImageOutput::create(png8);
    ASSERT_TRUE(out && out->open(png8, OIIO::ImageSpec(32, 32, 1, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, gray.data.data()) && out->close());
  }
  expect_input_error("filter --shadow-map " + png8 + " --receiver-depth " + png8, "uint8");

  // A perspective map in window depth with a block at window depth 0.9 over ground at 0.98.
  HostImage window(32, 32, 1, 0.98f);
  for (int y = 8; y < 16; ++y)
    for (int x = 8; x < 16; ++x) window.at(x, y) = 0.9f;
  io::write_image(path("window.exr"), window);
  auto receivers = [&](const std::string& name, float scale, float d) {
    HostImage rx(32, 32, 3);
    rx.channel_names = {"u", "v", "d"};
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        rx.at(x, y, 0) = (x + 0.5f) / 32 * scale;
        rx.at(x, y, 1) = (y + 0.5f) / 32 * scale;
        rx.at(x, y, 2) = d;
      }
    io::write_image(path(name), rx);
  };
  const std::string perspective = " --encoding perspective --near 1 --far 20 --method sm -q";
  // Receivers whose d is window depth, as the map's: decoded with the map's encoding, the ground
  // is lit and the block's shadow falls on it (before: 100% black).
  receivers("rx_window.exr", 1.0f, 0.98f);
  r = run_cli("filter --shadow-map " + path("window.exr") + " --receivers " + path("rx_window.exr") + perspective +
                  " -o " + path("window_vis.exr"),
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const HostImage wv = io::load_depth_map(path("window_vis.exr"), {});
  EXPECT_EQ(wv.at(11, 11), 0.0f);
  EXPECT_EQ(wv.at(24, 24), 1.0f);
  // Receivers with d in [0, 1] (linear) against the window-depth map: a warning naming the cause.
  receivers("rx_linear.exr", 1.0f, 0.6f);
  r = run_cli("filter --shadow-map " + path("window.exr") + " --receivers " + path("rx_linear.exr") + perspective +
                  " -o " + path("linear_vis.exr"),
              dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("warning: 100% of the receivers lie in front of the map's first surface"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--receiver-encoding"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(path("linear_vis.exr")));
  // Receivers with u, v in texels: a warning naming texel indices.
  receivers("rx_texels.exr", 32.0f, 0.98f);
  r = run_cli("filter --shadow-map " + path("window.exr") + " --receivers " + path("rx_texels.exr") + perspective +
                  " -o " + path("texel_vis.exr"),
              dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("of the receivers fall outside the map: u, v span [0.5, 31.5]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("texel indices?"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(path("texel_vis.exr")));
}

// What the camera route refuses: exit 2, one line, nothing written.
TEST_F(InputsCli, CameraInputsThatCannotBeReadAreRefused) {
  write_scene();
  const std::string rx = "receivers" + camera_args();
  expect_input_error(rx, "--shadow-map MAP or --map-size WxH");
  expect_input_error(rx + " --map-size 128", "--map-size must be WxH");
  ViewProjection transposed = light_.matrices();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < r; ++c) std::swap(transposed.view[size_t(r * 4 + c)], transposed.view[size_t(c * 4 + r)]);
  write_text("transposed.json", view_json(transposed));
  expect_input_error("receivers --camera " + path("camera.json") + " --camera-depth " + path("camera_depth.exr") +
                         " --light " + path("transposed.json") + " --map-size 128x128",
                     "transposed");
  expect_input_error(rx + " --map-size 128x128 --camera-depth-kind position", "camera depth");
  expect_input_error("filter --shadow-map " + path("map.exr") + " --camera " + path("camera.json") +
                         " --camera-depth " + path("camera_depth.exr"),
                     "--camera needs --light");
  expect_input_error("filter --shadow-map " + path("map.exr") + camera_args() + " --near 1 --far 9",
                     "--light gives the planes");
  write_text("bad.txt", "map.exr camera=camera.json out.exr\n");
  const RunResult frames = run_cli("filter --frames " + path("bad.txt"), dir_);
  EXPECT_EQ(frames.exit_code, 2);
  EXPECT_EQ(count_lines(frames.err), 1u) << frames.err;
  EXPECT_NE(frames.err.find("bad.txt:1: expected"), std::string::npos) << frames.err;
  const RunResult png = run_cli(rx + " --map-size 128x128 -o " + path("rx.png"), dir_);
  EXPECT_EQ(png.exit_code, 2);
  EXPECT_NE(png.err.find("float .exr or .tif"), std::string::npos) << png.err;
}

// Help a newcomer can read: every command's --help without CLI11's enum maps, within 80 columns
// when not a terminal, with an example; --version; --json where scripts read summaries.
TEST_F(InputsCli, HelpVersionAndJson) {
  for (const char* cmd :
       {"", "filter", "soft", "receivers", "scene", "devices", "methods", "evaluate", "evaluate-layouts", "coherent",
        "coherent build", "coherent merge", "coherent info", "coherent render", "coherent sky"}) {
    SCOPED_TRACE(cmd);
    const RunResult r = run_cli(std::string(cmd) + " --help", dir_);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.find("->"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(std::string(cmd).empty() ? "Start with" : "Example"), std::string::npos) << r.out;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 80u) << line;
  }
  for (const char* cmd : {"filter", "soft", "receivers"})
    EXPECT_NE(run_cli(std::string(cmd) + " --help", dir_).out.find("docs/inputs.md"), std::string::npos) << cmd;
  EXPECT_NE(run_cli("filter --help", dir_).out.find("Receivers: a float EXR/TIFF with channels u v d [f [ndl]]"),
            std::string::npos);
  RunResult r = run_cli("--version", dir_);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.rfind("shadowfilter 0.", 0), 0u) << r.out;
  r = run_cli("filter --lookup bogus", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--lookup: must be bilinear, mips or sat, got 'bogus'"), std::string::npos) << r.err;
  r = run_cli("filter --storage bogus", dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = run_cli("methods --json", dir_);
  ASSERT_EQ(r.exit_code, 0);
  const nlohmann::json methods = nlohmann::json::parse(r.out);
  ASSERT_TRUE(methods.is_array());
  EXPECT_EQ(methods[0]["name"], "sm");
  r = run_cli("devices --json", dir_);
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_TRUE(nlohmann::json::parse(r.out).is_array());
}

}  // namespace
}  // namespace sf::test

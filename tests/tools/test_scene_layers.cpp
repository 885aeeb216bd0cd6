// The scene side of layered shadow maps (host/scene/layer_render.hpp, scene_frames.hpp): the
// large scenes, the camera view as world positions (view.exr), the layers' depth maps, camera
// paths and their options. Tiny sizes: the whole file runs in seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <sstream>

#include "cascade_io.hpp"
#include "cli_runner.hpp"
#include "image_io.hpp"
#include "io_detail.hpp"
#include "layer_render.hpp"
#include "scene_generate.hpp"
#include "scene_render.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;
using namespace sf::scene;

// `shadowfilter scene ARGS` (cli_runner.hpp).
RunResult scene_cli(const std::string& args, const std::string& dir) { return run_cli("scene " + args, dir); }

SceneRequest tiny_request(const std::string& scene) {
  SceneRequest request;
  request.scene = scene;
  request.out_dir = "unused";
  request.map_size = 64;
  request.receivers = "64x48";
  request.samples = 1;
  request.progress = false;
  return request;
}

// "[a, b, c]" (json_vector) -> numbers.
std::vector<double> numbers_in(std::string text) {
  for (char& c : text)
    if (c == '[' || c == ']' || c == ',') c = ' ';
  std::istringstream in(text);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

double dot3(const std::vector<double>& a, double x, double y, double z) { return a[0] * x + a[1] * y + a[2] * z; }

// Both large scenes build, stay under their triangle budget, and cast shadows into the default
// camera's view (pixels facing the light but occluded).
TEST(SceneLayers, CityAndTreelineHaveShadows) {
  for (const char* name : {"city", "treeline"}) {
    SceneDefaults defaults;
    const SceneSetup setup = make_setup(tiny_request(name), &defaults);
    EXPECT_LT(setup.geometry.triangle_count(), 45000u) << name;
    EXPECT_GT(defaults.camera_far, 999.0) << name;
    EXPECT_FALSE(defaults.purpose.empty());
    const double elevation = std::asin(-setup.light.forward.y) * 180.0 / 3.14159265358979;
    EXPECT_TRUE(elevation >= 35.0 && elevation <= 50.0) << name << ": sun at " << elevation << " degrees";
    const SceneRenderer renderer(setup);
    const CameraImages view = renderer.camera_view(false);
    size_t hits = 0, shadowed = 0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        if (!std::isfinite(view.receivers.at(x, y, 2))) continue;
        ++hits;
        shadowed += view.receivers.at(x, y, 4) > 0.0f && view.reference_hard.at(x, y) == 0.0f;
      }
    std::printf("  %s: %zu triangles, %zu of %zu view pixels hit, %zu in shadow\n", name,
                setup.geometry.triangle_count(), hits, size_t(64 * 48), shadowed);
    EXPECT_GT(hits, 64u * 48u / 3) << name;
    EXPECT_GT(shadowed, hits / 50) << name;
    const HostImage sm = renderer.shadow_map(), ground = renderer.receiver_depth();
    EXPECT_LT(min_occluder_floor_gap(sm, ground), 1.0) << name << ": no occluder over the ground in the map";
  }
}

// view.exr and receivers.exr describe the same hits: every view pixel's P, projected through the
// scene's light (shadowmap.exr's header), gives receivers.exr's (u, v, d); background agrees. The
// layer files load back with the matrices the in-process fit gives for the same options.
TEST(SceneLayers, ViewMatchesReceiversAndLayersLoadBack) {
  const std::string dir = temp_dir("scene_layers_view");
  const std::string out = dir + "/city";
  const RunResult r =
      scene_cli("city -o " + out + " --size 64 --receivers 64x48 --samples 1 -q --layout pssm --cascades 3", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const ViewReceivers view = io::load_view_receivers(out + "/view.exr");
  const Receivers rx = io::load_receiver_image(out + "/receivers.exr");
  const io::detail::RawImage sm = io::detail::read_raw(out + "/shadowmap.exr", "shadow map");
  const auto right = numbers_in(sm.attributes.at("light_right")), down = numbers_in(sm.attributes.at("light_down")),
             forward = numbers_in(sm.attributes.at("light_direction")),
             extents = numbers_in(sm.attributes.at("ortho_extents"));
  const double near_plane = std::stod(sm.attributes.at("near")), far_plane = std::stod(sm.attributes.at("far"));
  ASSERT_EQ(view.count(), rx.count());
  size_t hits = 0;
  double worst = 0.0;
  for (size_t i = 0; i < view.count(); ++i) {
    ASSERT_EQ(std::isfinite(view.x[i]), std::isfinite(rx.d[i])) << "pixel " << i;
    if (!std::isfinite(view.x[i])) continue;
    ++hits;
    EXPECT_GT(view.depth[i], 0.0f);
    for (float o : {view.dxx[i], view.dxy[i], view.dxz[i], view.dyx[i], view.dyy[i], view.dyz[i]})
      ASSERT_TRUE(std::isfinite(o));
    const double u = (dot3(right, view.x[i], view.y[i], view.z[i]) - extents[0]) / (extents[1] - extents[0]);
    const double v = (dot3(down, view.x[i], view.y[i], view.z[i]) - extents[2]) / (extents[3] - extents[2]);
    const double d = (dot3(forward, view.x[i], view.y[i], view.z[i]) - near_plane) / (far_plane - near_plane);
    worst = std::max({worst, std::abs(u - rx.u[i]), std::abs(v - rx.v[i]), std::abs(d - rx.d[i])});
  }
  EXPECT_GT(hits, 1000u);
  EXPECT_LE(worst, 1e-4);

  SceneRequest request = tiny_request("city");
  request.layout.layout = "pssm";
  request.layout.cascades = 3;
  SceneDefaults defaults;
  const SceneSetup setup = make_setup(request, &defaults);
  const FramePlan plan = plan_frames(request.camera, request.layout, setup, defaults);
  const io::LayeredMaps loaded = io::load_cascade_set(io::cascade_files(out));
  ASSERT_EQ(loaded.set.layers.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(loaded.set.layers[k].transform.m, plan.frames[0].layers->layers[k].transform.m) << "layer " << k;
    EXPECT_EQ(loaded.set.layers[k].split_far, plan.frames[0].layers->layers[k].split_far);
    const auto& z = loaded.maps[k].data;
    EXPECT_TRUE(std::all_of(z.begin(), z.end(), [](float d) { return d >= 0.0f && d <= 1.0f; }));
    EXPECT_LT(*std::min_element(z.begin(), z.end()), 1.0f) << "layer " << k << " sees nothing";
  }
  EXPECT_NE(slurp(out + "/scene.json").find("\"world_to_map\""), std::string::npos);
}

// references_at, given a camera view's own points, traces what camera_view traced there: the
// hard reference the same but where P's float rounding crosses an edge, the soft one with the
// same light samples; under another light, other shadows.
TEST(SceneLayers, ReferencesAtTheViewsPointsAreTheViews) {
  SceneRequest request = tiny_request("city");
  request.samples = 16;
  SceneDefaults defaults;
  SceneSetup setup = make_setup(request, &defaults);
  setup.progress = false;
  const SceneRenderer renderer(setup);
  const CameraImages camera = renderer.camera_view(true);
  const ViewReceivers view = view_receivers(camera.view);
  const CameraImages again = renderer.references_at(view, setup.camera.position, true);
  size_t hits = 0, hard_differ = 0, shadowed = 0;
  double soft_diff = 0;
  for (size_t i = 0; i < view.count(); ++i) {
    if (!std::isfinite(view.depth[i])) {
      EXPECT_EQ(again.reference_hard.data[i], 1.0f);
      continue;
    }
    ++hits;
    shadowed += camera.reference_hard.data[i] == 0.0f;
    hard_differ += again.reference_hard.data[i] != camera.reference_hard.data[i];
    soft_diff += std::abs(again.reference_soft.data[i] - camera.reference_soft.data[i]);
  }
  std::printf("  %zu hits, %zu shadowed: %zu hard references differ, soft mean |diff| %.5f\n", hits, shadowed,
              hard_differ, soft_diff / hits);
  EXPECT_GT(hits, 1000u);
  EXPECT_GT(shadowed, hits / 50);
  EXPECT_LE(hard_differ, hits / 200);
  EXPECT_LT(soft_diff / hits, 0.005);
  SceneSetup turned = setup;
  turned.light = LightView::fit_ortho(setup.geometry, Vec3{0.8, -0.5, -0.3}, 0.01);
  const CameraImages other = SceneRenderer(turned).references_at(view, setup.camera.position, false);
  size_t moved = 0;
  for (size_t i = 0; i < view.count(); ++i)
    moved += std::isfinite(view.depth[i]) && other.reference_hard.data[i] != camera.reference_hard.data[i];
  EXPECT_GT(moved, hits / 20) << "another light casts other shadows";
}

// A `single` layer fitted without stabilisation is an orthographic map: the scene renderer's own
// shadow map, given the layer's light box (from its matrix rows), ray-traces the same depths at
// the same texels. Any thread count gives the same layer.
TEST(SceneLayers, SingleLayerMatchesRayTracedDepths) {
  for (const char* name : {"treeline", "spheres"}) {
    SceneSetup setup = make_setup(tiny_request(name));
    sf::LayoutOptions options;
    options.kind = sf::LayoutKind::Single;
    options.stabilize = false;
    options.map_size = 64;
    const ViewDepths depths = default_view_depths(setup.camera, setup.geometry);
    const sf::CascadeSet set =
        sf::fit_layout(options, camera_frustum(setup.camera, depths.near_depth, depths.far_depth),
                       to_point(setup.light.forward), geometry_boxes(setup.geometry));
    const SceneRenderer renderer(setup);
    const std::vector<HostImage> layers = render_layers(renderer.tracer(), set, 2, false);
    ASSERT_EQ(layers.size(), 1u);
    EXPECT_EQ(layers[0].data, render_layers(renderer.tracer(), set, 1, false)[0].data);

    const auto& m = set.layers[0].transform.m;
    const auto axis = [&](int r, Vec3& unit, Interval& range) {
      const Vec3 row{m[4 * r], m[4 * r + 1], m[4 * r + 2]};
      const double scale = length(row);
      unit = (1.0 / scale) * row;
      range.lo = -m[4 * r + 3] / scale;
      range.hi = range.lo + 1.0 / scale;
    };
    Interval depth;
    axis(0, setup.light.right, setup.light.right_range);
    axis(1, setup.light.down, setup.light.down_range);
    axis(2, setup.light.forward, depth);
    setup.light.near_plane = depth.lo;
    setup.light.far_plane = depth.hi;
    setup.map_width = setup.map_height = 64;
    const HostImage expected = SceneRenderer(setup).shadow_map();
    size_t off = 0, hit = 0;
    for (size_t t = 0; t < expected.data.size(); ++t) {
      off += std::abs(expected.data[t] - layers[0].data[t]) > 1e-5f;
      hit += expected.data[t] < 1.0f;
    }
    std::printf("  %s: %zu of %zu texels hit, %zu differ by > 1e-5\n", name, hit, expected.data.size(), off);
    EXPECT_GT(hit, expected.data.size() / 10) << name;
    EXPECT_LE(off, expected.data.size() / 200) << name;  // a ray on a silhouette may go either way
  }
}

// --frames N: frame_000 .. frame_N-1 with every camera file; the walk moves the camera along
// its look direction, the orbit keeps its height and distance from the look point.
TEST(SceneLayers, FramesMoveTheCamera) {
  const std::string dir = temp_dir("scene_layers_frames");
  const std::string out = dir + "/orbit";
  const RunResult r =
      scene_cli("spheres -o " + out +
                    " --size 32 --receivers 32x24 --samples 1 -q --frames 3 --camera-path orbit --layout single",
                dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* frame : {"frame_000", "frame_001", "frame_002"})
    for (const char* file : {"receivers.exr", "reference_hard.exr", "reference_soft.exr", "view.exr", "cascade_0.exr"})
      EXPECT_TRUE(fs::exists(fs::path(out) / frame / file)) << frame << "/" << file;
  EXPECT_FALSE(fs::exists(fs::path(out) / "frame_003"));
  EXPECT_TRUE(fs::exists(fs::path(out) / "shadowmap.exr"));
  EXPECT_FALSE(fs::exists(fs::path(out) / "receivers.exr"));
  EXPECT_NE(slurp(fs::path(out) / "frame_000/view.exr"), slurp(fs::path(out) / "frame_002/view.exr"));
  EXPECT_NE(slurp(fs::path(out) / "scene.json").find("\"dir\": \"frame_002\""), std::string::npos);

  for (const char* path : {"walk", "orbit"}) {
    SceneRequest request = tiny_request("city");
    request.camera.frames = 4;
    request.camera.path = path;
    SceneDefaults defaults;
    const SceneSetup setup = make_setup(request, &defaults);
    const FramePlan plan = plan_frames(request.camera, request.layout, setup, defaults);
    ASSERT_EQ(plan.frames.size(), 4u);
    const PerspectiveCamera &first = plan.frames.front().camera, &last = plan.frames.back().camera;
    EXPECT_GT(length(last.position - first.position), 10.0) << path;
    if (std::string(path) == "walk") {
      // 10% of far (1500 m) ahead, the look direction kept.
      EXPECT_NEAR(length(last.position - first.position), 150.0, 1e-6);
      EXPECT_NEAR(last.position.y, first.position.y, 1e-9);
      const Vec3 a = normalize(first.target - first.position), b = normalize(last.target - last.position);
      EXPECT_NEAR(length(a - b), 0.0, 1e-12);
    } else {
      EXPECT_NEAR(last.position.y, first.position.y, 1e-9);
      EXPECT_NEAR(length(last.position - last.target), length(first.position - first.target), 1e-6);
      EXPECT_EQ(last.target.x, first.target.x);
    }
  }
}

class SceneLayerErrors : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(SceneLayerErrors, ExitTwoOneLineNothingWritten) {
  const auto& [args, expect] = GetParam();
  const std::string dir = temp_dir("scene_layer_errors_" + std::to_string(std::hash<std::string>{}(args)));
  const RunResult r =
      scene_cli(std::string(args) + " --size 16 --receivers 16x12 --samples 1 -q -o " + dir + "/out", dir);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << "stderr: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "something was left in " << dir;
}

INSTANTIATE_TEST_SUITE_P(
    BadCameraOptions, SceneLayerErrors,
    ::testing::Values(std::make_pair("spheres --camera-fov 0", "--camera-fov must lie in [0.01, 170)"),
                      std::make_pair("city --camera-fov 170", "--camera-fov must lie in [0.01, 170)"),
                      std::make_pair("spheres --camera-near 0", "--camera-near and --camera-far"),
                      std::make_pair("city --camera-near 5 --camera-far 2", "--camera-near and --camera-far"),
                      std::make_pair("spheres --camera-pos 1,2,nan", "finite"),
                      std::make_pair("spheres --camera-pos 1,2,3 --camera-look 1,2,3", "must differ"),
                      std::make_pair("spheres --camera-look 7,50,9", "straight above or below"),
                      std::make_pair("spheres --camera-pos 0,2,-30 --camera-look 0,2,-60", "behind the camera"),
                      std::make_pair("spheres --frames 0", "--frames must lie in 1..1000"),
                      std::make_pair("treeline --frames 1001", "--frames must lie in 1..1000"),
                      std::make_pair("spheres --camera-path zigzag", "--camera-path must be walk or orbit"),
                      std::make_pair("spheres --camera-path orbit --camera-to 1,2,3", "--camera-to needs"),
                      std::make_pair("spheres --orbit-degrees 20", "--orbit-degrees needs"),
                      std::make_pair("spheres --layout cubic", "unknown layout 'cubic'"),
                      std::make_pair("spheres --cascades 3", "need --layout"),
                      std::make_pair("spheres --layout pssm --cascades 9", "--cascades must lie in 1..8"),
                      std::make_pair("spheres --layout pssm --split-lambda 2", "--split-lambda must lie in [0, 1]"),
                      std::make_pair("spheres --layout tsm --cascade-blend 1", "--cascade-blend must lie in [0, 1)"),
                      std::make_pair("spheres --layout single --light perspective", "--layout needs --light ortho")));

}  // namespace
}  // namespace sf::test

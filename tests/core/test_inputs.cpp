// Inputs rendered elsewhere (docs/inputs.md), in process: the light's projection as a map
// encoding, the camera and light files, receivers from a camera against hand-computed values, and
// the filtered visibility of an analytic scene against its ray-cast truth, for the conventions
// real renderers use (OpenGL, D3D, Vulkan, reversed-Z, world units).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "analytic_setups.hpp"
#include "camera_io.hpp"
#include "expect_input_error.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/depth_encoding.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/view_projection.hpp"

namespace sf::test {
namespace {

using namespace analytic;

// --- a light's projection as its map's encoding -----------------------------------------------

// For each kind of projection, the window depth of points along the light's axis decodes to
// d = (z - N) / (F - N) of their distance z.
TEST(LightEncoding, WindowDepthOfEveryProjectionDecodesToLinearDepth) {
  struct Case {
    const char* name;
    View light;
    DepthEncoding expected;
  };
  const Case cases[] = {
      {"gl ortho", ortho_light(ClipSpace::OpenGL), DepthEncoding::Linear},
      {"d3d ortho", ortho_light(ClipSpace::D3D), DepthEncoding::Linear},
      {"gl perspective", spot_light(ClipSpace::OpenGL, Depth::Conventional), DepthEncoding::Perspective},
      {"d3d perspective", spot_light(ClipSpace::D3D, Depth::Conventional), DepthEncoding::Perspective},
      {"vulkan reversed", spot_light(ClipSpace::Vulkan, Depth::Reversed), DepthEncoding::Reversed},
      {"d3d reversed infinite", spot_light(ClipSpace::D3D, Depth::ReversedInfinite), DepthEncoding::ReversedInfinite},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const DepthDecoding decoding = window_depth_decoding(c.light.matrices());
    EXPECT_EQ(decoding.encoding, c.expected);
    const ProjectionDepth pd = light_projection_depth(c.light.matrices());
    EXPECT_NEAR(pd.near_plane, c.light.near_plane, 1e-9);
    EXPECT_NEAR(pd.far_plane, c.light.far_plane, 1e-9);
    for (double t : {0.0, 0.1, 0.37, 0.5, 0.9, 1.0}) {
      const double z = c.light.near_plane + t * (c.light.far_plane - c.light.near_plane);
      const V3 p = c.light.eye + z * c.light.forward;
      EXPECT_NEAR(decode_depth(c.light.window_depth(p), decoding), t, 1e-9) << "t=" << t;
    }
  }
}

// OpenGL's window depth with the default glDepthRange and D3D's [0, 1] depth are the same
// hyperbola; OpenGL's NDC z is not.
TEST(LightEncoding, OpenGlWindowDepthEqualsD3dDepthButNotNdc) {
  const View gl = spot_light(ClipSpace::OpenGL, Depth::Conventional),
             d3d = spot_light(ClipSpace::D3D, Depth::Conventional);
  const V3 p = gl.eye + 5.0 * gl.forward;
  EXPECT_NEAR(gl.window_depth(p), d3d.window_depth(p), 1e-12);
  DepthDecoding ndc{DepthEncoding::PerspectiveNdc, gl.near_plane, gl.far_plane};
  EXPECT_NEAR(decode_depth(2.0 * gl.window_depth(p) - 1.0, ndc), gl.d(p), 1e-12);
}

TEST(LightEncoding, AnInfiniteFarPlaneNeedsTheDepthOfDOne) {
  ViewProjection vp = spot_light(ClipSpace::D3D, Depth::ReversedInfinite).matrices();
  vp.infinite_far_depth = NAN;
  EXPECT_NO_THROW(projection_depth(vp));  // a camera's may stay infinite
  expect_input_error([&] { light_projection_depth(vp); }, {"infinite far plane", "infinite_far_depth"});
}

// --- camera and light files ---------------------------------------------------------------------

TEST(ViewFile, ParsesMatricesClipAndFar) {
  const View light = spot_light(ClipSpace::D3D, Depth::ReversedInfinite);
  const io::ViewFile f = io::parse_view_file(
      view_json(light.matrices(),
                ", \"clip\": \"d3d\", \"reversed_z\": true, \"far\": 16, \"width\": 128, \"height\": 128"),
      "light 'l.json'");
  EXPECT_EQ(f.view_projection.clip, ClipSpace::D3D);
  EXPECT_EQ(f.view_projection.reversed_z, std::optional<bool>(true));
  EXPECT_EQ(f.view_projection.infinite_far_depth, 16.0);
  EXPECT_EQ(f.width, 128);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(f.view_projection.view[size_t(i)], light.view_matrix()[size_t(i)], 1e-6);
  // Four rows of four are the same matrix.
  const io::ViewFile rows = io::parse_view_file(
      "{\"view\": [[1,0,0,0],[0,1,0,0],[0,0,1,-5],[0,0,0,1]], \"projection\": [[1,0,0,0],[0,1,0,0],"
      "[0,0,-1.2,-2.2],[0,0,-1,0]]}",
      "camera 'c.json'");
  EXPECT_EQ(rows.view_projection.view[11], -5.0);
  EXPECT_EQ(rows.view_projection.clip, ClipSpace::OpenGL);
}

TEST(ViewFile, RefusesWhatIsNotACameraInOneLine) {
  const ViewProjection vp = spot_light(ClipSpace::OpenGL, Depth::Conventional).matrices();
  ViewProjection transposed_view = vp, transposed_projection = vp;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      transposed_view.view[size_t(r * 4 + c)] = vp.view[size_t(c * 4 + r)];
      transposed_projection.projection[size_t(r * 4 + c)] = vp.projection[size_t(c * 4 + r)];
    }
  const std::string src = "light 'l.json'";
  expect_input_error([&] { io::parse_view_file("{\"view\": [1, 2", src); }, {src, "not JSON"});
  expect_input_error([&] { io::parse_view_file("[1, 2]", src); }, {src, "expected an object"});
  expect_input_error([&] { io::parse_view_file(view_json(vp, ", \"fov\": 60"), src); }, {src, "unknown key \"fov\""});
  expect_input_error([&] { io::parse_view_file("{\"view\": [1,2,3], \"projection\": [[1]]}", src); },
                     {src, "must be 16 numbers", "got array of "});
  expect_input_error([&] { io::parse_view_file(view_json(vp, ", \"clip\": \"metal\""), src); }, {src, "\"clip\""});
  expect_input_error([&] { io::parse_view_file("{\"view\": [1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}", src); },
                     {src, "\"projection\" is missing"});
  expect_input_error([&] { io::parse_view_file(view_json(transposed_view), src); }, {src, "transposed"});
  expect_input_error([&] { io::parse_view_file(view_json(transposed_projection), src); }, {src, "transposed"});
  expect_input_error([&] { io::parse_view_file(view_json(vp, ", \"reversed_z\": true"), src); },
                     {src, "\"reversed_z\" is true", "window depth 0"});
  expect_input_error([&] { io::parse_view_file(std::string(100, '[') + std::string(100, ']'), src); },
                     {src, "nested deeper"});
  ViewProjection singular = vp;
  singular.projection.fill(0.0);
  expect_input_error([&] { io::parse_view_file(view_json(singular), src); }, {src, "singular"});
}

// --- receivers from a camera --------------------------------------------------------------------

CameraDepth depth_buffer(const CameraTruth& truth, const View& cam) {
  CameraDepth d;
  d.width = cam.width;
  d.height = cam.height;
  d.kind = CameraDepthKind::Window;
  d.values = truth.window;
  return d;
}

// A pixel away from silhouettes and creases: its 5x5 neighbourhood sees one surface (the
// differences a normal is reconstructed from reach two pixels).
bool interior(const CameraTruth& t, int x, int y, int w, int h) {
  const int s = t.surface[size_t(y) * w + x];
  if (s < 0) return false;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= w || yy >= h || t.surface[size_t(yy) * w + xx] != s) return false;
    }
  return true;
}

// The footprint by its definition (camera_receivers.hpp) on the true tangent plane.
double footprint_truth(const View& cam, const View& light, int x, int y, V3 p, V3 n) {
  auto edge = [&](double px, double py) {
    V3 o, d;
    cam.ray(px, py, &o, &d);
    return o + (dot(p - o, n) / dot(d, n)) * d;
  };
  auto texels = [&](V3 a, V3 b) {
    double ua, va, ub, vb;
    light.uv(a, &ua, &va);
    light.uv(b, &ub, &vb);
    return std::hypot((ub - ua) * light.width, (vb - va) * light.height);
  };
  return std::max(texels(edge(x, y + 0.5), edge(x + 1.0, y + 0.5)), texels(edge(x + 0.5, y), edge(x + 0.5, y + 1.0)));
}

struct ReceiverCase {
  const char* name;
  View camera, light;
};

std::vector<ReceiverCase> receiver_cases() {
  return {
      {"gl camera, gl ortho light", camera_view(ClipSpace::OpenGL, Depth::Conventional),
       ortho_light(ClipSpace::OpenGL)},
      {"d3d camera, gl spot light", camera_view(ClipSpace::D3D, Depth::Conventional),
       spot_light(ClipSpace::OpenGL, Depth::Conventional)},
      {"reversed infinite d3d camera, reversed vulkan spot light", camera_view(ClipSpace::D3D, Depth::ReversedInfinite),
       spot_light(ClipSpace::Vulkan, Depth::Reversed)},
      {"vulkan camera, d3d ortho light", camera_view(ClipSpace::Vulkan, Depth::Conventional),
       ortho_light(ClipSpace::D3D)},
  };
}

// u, v, d within 1e-5 of the values computed from the ray-cast point, on every surface pixel; f
// within 5% and ndl within 0.02 away from silhouettes and creases (which the depth buffer alone
// cannot tell from surfaces); background pixels NaN.
TEST(CameraReceivers, MatchHandComputedValues) {
  const Scene scene;
  for (const ReceiverCase& c : receiver_cases()) {
    SCOPED_TRACE(c.name);
    const CameraTruth truth = render_camera(scene, c.camera);
    CameraReceiverOptions opt;
    opt.map_width = c.light.width;
    opt.map_height = c.light.height;
    CameraReceiverCounts counts;
    const Receivers rx =
        camera_receivers(c.camera.matrices(), depth_buffer(truth, c.camera), c.light.matrices(), opt, &counts);
    ASSERT_EQ(rx.width, c.camera.width);
    ASSERT_EQ(rx.count(), truth.surface.size());
    EXPECT_TRUE(rx.has_footprint && rx.has_ndl);
    size_t surface = 0, checked = 0, background = 0;
    double worst_uvd = 0, worst_f = 0, worst_ndl = 0;
    for (int y = 0; y < c.camera.height; ++y)
      for (int x = 0; x < c.camera.width; ++x) {
        const size_t i = size_t(y) * c.camera.width + x;
        if (truth.surface[i] < 0) {
          ++background;
          EXPECT_TRUE(std::isnan(rx.d[i]) && std::isnan(rx.u[i]) && std::isnan(rx.f[i])) << x << "," << y;
          continue;
        }
        ++surface;
        const V3 p = truth.point[i], n = truth.normal[i];
        double u, v;
        c.light.uv(p, &u, &v);
        const double d = c.light.d(p);
        if (u < 0 || u > 1 || v < 0 || v > 1 || d < 0 || d > 1) continue;  // outside the light: not these numbers
        worst_uvd = std::max({worst_uvd, std::fabs(rx.u[i] - u), std::fabs(rx.v[i] - v), std::fabs(rx.d[i] - d)});
        if (!interior(truth, x, y, c.camera.width, c.camera.height)) continue;
        ++checked;
        const double f = footprint_truth(c.camera, c.light, x, y, p, n);
        worst_f = std::max(worst_f, std::fabs(rx.f[i] - f) / f);
        worst_ndl = std::max(worst_ndl, std::fabs(rx.ndl[i] - dot(n, c.light.to_light(p))));
      }
    EXPECT_EQ(counts.background, background);
    EXPECT_GT(checked, surface / 2) << "the comparison must cover most of the picture";
    EXPECT_GT(background, 0u);
    EXPECT_LE(worst_uvd, 1e-5);
    EXPECT_LE(worst_f, 0.05);
    EXPECT_LE(worst_ndl, 0.02);
  }
}

// The same receivers from the other kinds of camera depth: distance along the axis (Blender's Z
// pass, with 1e10 on the background), along the ray, and world positions.
TEST(CameraReceivers, EveryKindOfCameraDepthGivesTheSameReceivers) {
  const Scene scene;
  const View cam = camera_view(ClipSpace::OpenGL, Depth::Conventional), light = ortho_light(ClipSpace::OpenGL);
  const CameraTruth truth = render_camera(scene, cam);
  CameraReceiverOptions opt;
  opt.map_width = opt.map_height = kMapSize;
  const Receivers reference = camera_receivers(cam.matrices(), depth_buffer(truth, cam), light.matrices(), opt);
  CameraDepth view, distance, position;
  for (CameraDepth* d : {&view, &distance, &position}) d->width = cam.width, d->height = cam.height;
  view.kind = CameraDepthKind::View;
  distance.kind = CameraDepthKind::Distance;
  position.kind = CameraDepthKind::Position;
  for (size_t i = 0; i < truth.surface.size(); ++i) {
    const bool hit = truth.surface[i] >= 0;
    const V3 p = truth.point[i];
    view.values.push_back(hit ? float(cam.axis_distance(p)) : 1e10f);
    distance.values.push_back(hit ? float(std::sqrt(dot(p - cam.eye, p - cam.eye))) : NAN);
    for (double c : {p.x, p.y, p.z}) position.values.push_back(hit ? float(c) : NAN);
  }
  for (const CameraDepth* d : {&view, &distance, &position}) {
    SCOPED_TRACE(camera_depth_kind_name(d->kind));
    const Receivers rx = camera_receivers(cam.matrices(), *d, light.matrices(), opt);
    double worst = 0;
    for (size_t i = 0; i < rx.count(); ++i) {
      EXPECT_EQ(std::isnan(rx.d[i]), std::isnan(reference.d[i])) << i;
      if (std::isnan(reference.d[i]) || reference.u[i] < 0) continue;
      worst =
          std::max({worst, double(std::fabs(rx.u[i] - reference.u[i])), double(std::fabs(rx.d[i] - reference.d[i]))});
    }
    EXPECT_LE(worst, 2e-5);
  }
}

TEST(CameraReceivers, RefuseMisreadInputs) {
  const View cam = camera_view(ClipSpace::OpenGL, Depth::Conventional), light = ortho_light(ClipSpace::OpenGL);
  CameraDepth d;
  d.width = 4, d.height = 3;
  d.values.assign(12, 7.5f);  // world units handed over as window depth
  CameraReceiverOptions opt;
  opt.map_width = opt.map_height = 64;
  expect_input_error([&] { camera_receivers(cam.matrices(), d, light.matrices(), opt); },
                     {"[7.5, 7.5]", "window depth's [0, 1]", "CameraDepth::kind view"});
  d.values.assign(11, 0.5f);
  expect_input_error([&] { camera_receivers(cam.matrices(), d, light.matrices(), opt); }, {"11 values", "12"});
  d.values.assign(12, 0.5f);
  opt.map_width = 0;
  expect_input_error([&] { camera_receivers(cam.matrices(), d, light.matrices(), opt); }, {"map_width"});
}

// --- the filtered result against the ray-cast truth ---------------------------------------------

struct ShadowCase {
  const char* name;
  View camera, light;
  Store store;  // the map as the light's window depth, or in world units along its axis
};

// The map written as a file and read back as the CLI reads it: window depth decoded by the
// light's projection, or world units with the light's planes.
HostImage load_map(const std::string& dir, const ShadowCase& c) {
  const Scene scene;
  const std::string path = dir + "/map.exr";
  io::write_image(path, render_map(scene, c.light, c.store));
  const DepthDecoding window = window_depth_decoding(c.light.matrices());
  io::DepthLoadOptions opt;
  opt.encoding = c.store == Store::World ? DepthEncoding::Linear : window.encoding;
  opt.near_plane = c.store == Store::World ? c.light.near_plane : window.near_plane;
  opt.far_plane = c.store == Store::World ? c.light.far_plane : window.far_plane;
  return io::load_depth_map(path, opt);
}

// sm with its defaults (the receiver plane, bilinear): on every convention the mismatched pixels
// away from shadow edges stay under 0.5%.
TEST(AnalyticShadows, FilterOfCameraReceiversMatchesTheRayCastTruth) {
  const Scene scene;
  const std::string dir = temp_dir("analytic_shadows");
  const ShadowCase cases[] = {
      {"ortho light in world units, gl camera", camera_view(ClipSpace::OpenGL, Depth::Conventional),
       ortho_light(ClipSpace::OpenGL), Store::World},
      {"gl spot light window depth, d3d camera", camera_view(ClipSpace::D3D, Depth::Conventional),
       spot_light(ClipSpace::OpenGL, Depth::Conventional), Store::Window},
      {"d3d reversed-Z spot light, reversed infinite camera", camera_view(ClipSpace::D3D, Depth::ReversedInfinite),
       spot_light(ClipSpace::D3D, Depth::Reversed), Store::Window},
      {"d3d reversed-Z infinite spot light, vulkan camera", camera_view(ClipSpace::Vulkan, Depth::Conventional),
       spot_light(ClipSpace::D3D, Depth::ReversedInfinite), Store::Window},
      {"gl ortho light window depth, gl camera", camera_view(ClipSpace::OpenGL, Depth::Conventional),
       ortho_light(ClipSpace::OpenGL), Store::Window},
  };
  FilterOptions options;
  options.method = "sm";
  for (const ShadowCase& c : cases) {
    SCOPED_TRACE(c.name);
    const HostImage map = load_map(dir, c);
    const CameraTruth truth = render_camera(scene, c.camera);
    CameraReceiverOptions opt;
    opt.map_width = map.width;
    opt.map_height = map.height;
    const Receivers rx = camera_receivers(c.camera.matrices(), depth_buffer(truth, c.camera), c.light.matrices(), opt);
    const FilterResult r = filter(runtime_ptr(), options, map, rx);
    const Mismatches m = compare_with_truth(scene, c.light, truth, r.visibility.data);
    EXPECT_GT(m.compared, 8000u);
    EXPECT_LE(m.fraction(), 0.005) << m.mismatched << " of " << m.compared << " (" << m.skipped << " near edges)";
    // Both lit and shadowed pixels are compared: the scene casts shadows the map must hold.
    size_t shadowed = 0;
    for (size_t i = 0; i < truth.surface.size(); ++i) shadowed += truth.surface[i] >= 0 && r.visibility.data[i] < 0.5f;
    EXPECT_GT(shadowed, 1500u);
  }
}

// The comparison can fail: the same window-depth map read as linear depth (the mistake the
// encodings exist for) mismatches far more than 0.5% of the pixels.
TEST(AnalyticShadows, AMisreadMapFailsTheComparison) {
  const Scene scene;
  const View camera = camera_view(ClipSpace::OpenGL, Depth::Conventional);
  const View light = spot_light(ClipSpace::OpenGL, Depth::Conventional);
  const std::string path = temp_dir("analytic_misread") + "/map.exr";
  io::write_image(path, render_map(scene, light, Store::Window));
  const HostImage map = io::load_depth_map(path, {});  // linear: wrong
  const CameraTruth truth = render_camera(scene, camera);
  CameraReceiverOptions opt;
  opt.map_width = map.width;
  opt.map_height = map.height;
  const Receivers rx = camera_receivers(camera.matrices(), depth_buffer(truth, camera), light.matrices(), opt);
  FilterOptions options;
  options.method = "sm";
  const Mismatches m = compare_with_truth(scene, light, truth, filter(runtime_ptr(), options, map, rx).visibility.data);
  EXPECT_GT(m.fraction(), 0.05) << m.mismatched << " of " << m.compared;
}

}  // namespace
}  // namespace sf::test

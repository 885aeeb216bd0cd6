// Layered filtering (layered.hpp, kernels/cascade.cl, host/reference/cascade_reference.hpp, the
// CLI's --cascades): an analytic scene (a ground plane y = 0, a box above it, an orthographic
// light, a perspective camera) whose layer maps are ray-cast per texel, so every layout of
// sf::fit_layout can be checked against the single map and against the geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cascade_io.hpp"
#include "cascade_reference.hpp"
#include "cli_runner.hpp"
#include "image_io.hpp"
#include "lookups.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/soft.hpp"

namespace sf {
namespace {

using test::runtime_ptr;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// ---- the scene ------------------------------------------------------------------------------

struct Scene {
  CameraFrustum camera;
  Point3 light;       // the direction the light travels
  WorldBox occluder;  // a slab floating above the ground
  WorldBox ground;    // the part of the plane y = 0 the fits see
};

const Scene& scene() {
  static const Scene s = [] {
    Scene s;
    s.camera.position = {0, 7, 7};
    s.camera.forward = normalize(Point3{0, 0, 0} - s.camera.position);
    const Point3 right = normalize(cross(s.camera.forward, {0, 1, 0}));
    s.camera.up = cross(right, s.camera.forward);
    s.camera.vertical_fov_degrees = 50;
    s.camera.aspect = 16.0 / 9.0;
    s.camera.near_depth = 4.0;
    s.camera.far_depth = 20.0;
    s.light = normalize(Point3{0.2, -1.0, 1.0});
    s.occluder = {{-3.0, 1.5, -3.0}, {3.0, 2.0, 3.0}};
    s.ground = {{-60, -0.01, -60}, {60, 0, 60}};
    return s;
  }();
  return s;
}

struct Hit {
  double t = kInf;
  Point3 n{0, 0, 0};
};

Hit hit_box(const WorldBox& b, const Point3& o, const Point3& d) {
  double t0 = -kInf, t1 = kInf;
  Hit h;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return {};
      continue;
    }
    const double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (std::min(ta, tb) > t0) {
      t0 = std::min(ta, tb);
      h.n = {0, 0, 0};
      h.n[a] = d[a] > 0 ? -1.0 : 1.0;
    }
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (t0 > t1 || t1 < 0) return {};
  h.t = std::max(t0, 0.0);
  return h;
}

Hit trace(const Point3& o, const Point3& d) {
  Hit h = hit_box(scene().occluder, o, d);
  if (d[1] < 0) {
    const double t = -o[1] / d[1];
    if (t >= 0 && t < h.t) h = Hit{t, {0, 1, 0}};
  }
  return h;
}

// A ground point is in the box's shadow when the ray towards the light meets the box.
bool shadowed(const Point3& p) { return std::isfinite(hit_box(scene().occluder, p, (-1.0 * scene().light)).t); }

CascadeSet layout(LayoutKind kind, int size = 128, double blend = 0.1) {
  LayoutOptions o;
  o.kind = kind;
  o.cascades = 3;
  o.map_size = size;
  o.blend = blend;
  return fit_layout(o, scene().camera, scene().light, {scene().ground, scene().occluder});
}

// Each texel's light ray (LayerTransform::ray) against the scene: the linear depth of the first
// hit, 1 where nothing is hit within the layer's depth range.
std::vector<HostImage> render_maps(const CascadeSet& set) {
  std::vector<HostImage> maps;
  for (const CascadeLayer& layer : set.layers) {
    HostImage m(set.width, set.height, 1, 1.0f);
    for (int y = 0; y < set.height; ++y)
      for (int x = 0; x < set.width; ++x) {
        Point3 o, d;
        double per_length = 0;
        if (!layer.transform.ray((x + 0.5) / set.width, (y + 0.5) / set.height, o, d, per_length)) continue;
        const Hit h = trace(o, d);
        if (std::isfinite(h.t)) m.at(x, y) = float(std::clamp(h.t * per_length, 0.0, 1.0));
      }
    maps.push_back(std::move(m));
  }
  return maps;
}

// The camera's view: per pixel the first hit, its view depth, the offsets to the points of its
// tangent plane half a pixel to either side, n.l; background beyond the far plane.
ViewReceivers render_view(int width, int height) {
  const CameraFrustum& cam = scene().camera;
  const Point3 right = cross(cam.forward, cam.up);
  const double tan_half = std::tan(0.5 * cam.vertical_fov_degrees * M_PI / 180.0);
  const auto ray = [&](double sx, double sy) {
    const double nx = (2.0 * sx / width - 1.0) * tan_half * cam.aspect, ny = (1.0 - 2.0 * sy / height) * tan_half;
    return (cam.forward + ((nx * right) + (ny * cam.up)));
  };
  ViewReceivers v;
  v.width = width;
  v.height = height;
  std::vector<float>* all[] = {&v.x, &v.y, &v.z, &v.depth, &v.dxx, &v.dxy, &v.dxz, &v.dyx, &v.dyy, &v.dyz, &v.ndl};
  for (auto* a : all) a->assign(v.count(), kNaN);
  for (int py = 0; py < height; ++py)
    for (int px = 0; px < width; ++px) {
      const size_t i = size_t(py) * width + px;
      const Point3 d = ray(px + 0.5, py + 0.5);
      const Hit h = trace(cam.position, d);
      if (!(h.t <= cam.far_depth)) continue;
      const Point3 p = (cam.position + (h.t * d));
      const auto on_plane = [&](const Point3& r) {
        return (cam.position + (dot(h.n, (p - cam.position)) / dot(h.n, r) * r));
      };
      const Point3 dx = (on_plane(ray(px + 1.0, py + 0.5)) - on_plane(ray(px, py + 0.5)));
      const Point3 dy = (on_plane(ray(px + 0.5, py + 1.0)) - on_plane(ray(px + 0.5, py)));
      v.x[i] = float(p[0]), v.y[i] = float(p[1]), v.z[i] = float(p[2]);
      v.depth[i] = float(h.t);  // forward . d = 1
      v.dxx[i] = float(dx[0]), v.dxy[i] = float(dx[1]), v.dxz[i] = float(dx[2]);
      v.dyx[i] = float(dy[0]), v.dyy[i] = float(dy[1]), v.dyz[i] = float(dy[2]);
      v.ndl[i] = float(-dot(h.n, scene().light));
    }
  return v;
}

Point3 position(const ViewReceivers& v, size_t i) { return {v.x[i], v.y[i], v.z[i]}; }

// ---- device helpers -------------------------------------------------------------------------

struct DeviceView {
  DeviceReceivers rx;
  cl::Buffer visibility;
};
DeviceView upload(const ViewReceivers& v) {
  DeviceView d;
  d.rx = upload_view_receivers(test::runtime(), v);
  d.visibility = test::to_device(std::vector<float>(v.count(), -1.0f));
  return d;
}

std::vector<cl_char2> read_choice(const LayeredPipeline& pipe) {
  std::vector<cl_char2> out(pipe.projection().count);
  test::runtime().queue().enqueueReadBuffer(pipe.projection().layers, CL_TRUE, 0, out.size() * sizeof(cl_char2),
                                            out.data());
  return out;
}

// The kernel's projection as the reference takes it.
ref::CascadeProjection read_projection(const LayeredPipeline& pipe, const ViewReceivers& view) {
  const auto& p = pipe.projection();
  const std::vector<cl_char2> layers = read_choice(pipe);
  const std::vector<float> weight = test::from_device(p.weight, p.count);
  const int K = pipe.layer_count();
  const std::vector<float> u = test::from_device(p.u, K * p.stride), v = test::from_device(p.v, K * p.stride);
  const std::vector<float> d = test::from_device(p.d, K * p.stride), f = test::from_device(p.f, K * p.stride);
  const std::vector<float> jac = p.jacobian() ? test::from_device(p.jacobian, 4 * K * p.stride) : std::vector<float>();
  const auto jac_plane = [&](int k, int c) {
    const auto first = jac.begin() + 4 * k * p.stride + c * p.count;
    return std::vector<float>(first, first + p.count);
  };
  ref::CascadeProjection out;
  for (size_t i = 0; i < p.count; ++i) {
    CascadeChoice c;
    c.layer[0] = layers[i].s[0];
    c.layer[1] = layers[i].s[1];
    c.weight[0] = c.layer[0] >= 0 ? 1.0 - weight[i] : 0.0;
    c.weight[1] = c.layer[1] >= 0 ? weight[i] : 0.0;
    out.choice.push_back(c);
  }
  for (int k = 0; k < K; ++k) {
    Receivers rx;
    rx.width = view.width;
    rx.height = view.height;
    rx.has_footprint = true;
    const auto plane = [&](const std::vector<float>& a) {
      return std::vector<float>(a.begin() + k * p.stride, a.begin() + k * p.stride + p.count);
    };
    rx.u = plane(u), rx.v = plane(v), rx.d = plane(d), rx.f = plane(f);
    if (p.jacobian()) {  // four planes of count floats from 4 k stride
      rx.has_jacobian = true;
      std::vector<float>* planes[4] = {&rx.dudx, &rx.dvdx, &rx.dudy, &rx.dvdy};
      for (int c = 0; c < 4; ++c) *planes[c] = jac_plane(k, c);
    }
    out.layers.push_back(std::move(rx));
  }
  return out;
}

// Runs a LayeredPipeline on host maps and a view: the visibility (the pipeline keeps the rest).
std::vector<float> run(LayeredPipeline& pipe, const std::vector<HostImage>& maps, const ViewReceivers& view) {
  std::vector<cl::Buffer> depth;
  for (const HostImage& m : maps) depth.push_back(test::to_device(m.data));
  const DeviceView d = upload(view);
  EventList filtered{pipe.prefilter(depth)};
  pipe.reconstruct(d.rx, d.visibility, &filtered).wait();
  return test::from_device(d.visibility, view.count());
}

constexpr int kMapSize = 160;  // the scene test's layer maps

const std::vector<LayoutKind>& all_layouts() {
  static const std::vector<LayoutKind> k{LayoutKind::Single, LayoutKind::Pssm, LayoutKind::Tsm, LayoutKind::PssmTsm};
  return k;
}

// ---- (a) every layout against the single map and the geometry -------------------------------

// Whether every texel within `texels` of p's map point in layer k (a square, step one texel)
// lies on the map and sees what p sees: the box over a shadowed ground point, the ground over a
// lit one. In texels of the layer itself, so a warped layer's stretched texels count as they
// are. Near the map's edge the lookups clamp, and the receiver plane, extrapolated onto the
// clamped texels, is no longer the scene's (a tight tsm fit puts the far plane on its last row).
bool layer_resolves(const CascadeSet& set, int k, const Point3& p, int texels) {
  const LayerTransform& t = set.layers[k].transform;
  const LayerTransform::MapPoint q = t.apply(p);
  const bool centre = shadowed(p);
  for (int dy = -texels; dy <= texels; ++dy)
    for (int dx = -texels; dx <= texels; ++dx) {
      Point3 o, d;
      double per_length = 0;
      const double u = q.u + double(dx) / set.width, v = q.v + double(dy) / set.height;
      if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0)) return false;  // clamp-to-edge: not the scene
      if (!t.ray(u, v, o, d, per_length)) return false;
      const double along = -o[1] / d[1];
      if (shadowed((o + (along * d))) != centre) return false;
    }
  return true;
}

bool ground_around(const ViewReceivers& v, size_t i, int pixels) {
  const int x = int(i % v.width), y = int(i / v.width);
  for (int dy = -pixels; dy <= pixels; ++dy)
    for (int dx = -pixels; dx <= pixels; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= v.width || yy >= v.height) return false;
      const size_t j = size_t(yy) * v.width + xx;
      if (!std::isfinite(v.depth[j]) || std::abs(v.y[j]) > 1e-4) return false;
    }
  return true;
}

struct SceneCase {
  const char* method;
  int radius;
  double tolerance;  // |layout - single| and |layout - truth| where both resolve the receiver
};

// sm and pcf are exact away from the shadow's edge: every texel of the support is the ground
// (lit, the receiver plane takes its slope) or the box (shadowed). ESM's shadow leaks
// exp(-c (d - z)), d - z the box's height over the ground in each layer's depth units, where the
// classification's PCF fall-back does not take the receiver: 5e-3 bounds it for the default c.
class LayeredScene : public ::testing::TestWithParam<SceneCase> {};

TEST_P(LayeredScene, EveryLayoutMatchesTheSingleMapWhereBothResolve) {
  const SceneCase& c = GetParam();
  const ViewReceivers view = render_view(192, 108);
  std::vector<CascadeSet> sets;
  std::vector<LayeredResult> results;
  FilterOptions opt;
  opt.method = c.method;
  opt.blur.radius = c.radius;
  // Defaults otherwise: a warped layer's slope-scaled bias comes from layer_filter_options
  // (kWarpedSlopeBias), which this test holds to keeping lit ground lit under every warp.
  for (LayoutKind kind : all_layouts()) {
    sets.push_back(layout(kind, kMapSize));
    results.push_back(filter_layered(runtime_ptr(), opt, sets.back(), render_maps(sets.back()), view));
  }
  std::vector<size_t> lit(sets.size()), dark(sets.size());
  for (size_t i = 0; i < view.count(); ++i) {
    // Ground receivers whose neighbours in the view, two pixels each way, are ground too: the
    // receiver plane comes from them (a silhouette's neighbour is the per-map rule's business).
    if (!ground_around(view, i, 2)) continue;
    const Point3 p = position(view, i);
    const int truth = shadowed(p) ? 0 : 1;
    // Resolved by a layout: every layer it reads here sees one kind of surface for 3 texels plus
    // the blur's radius around the receiver.
    std::vector<bool> resolved;
    for (const CascadeSet& set : sets) {
      const CascadeChoice ch = select_cascade(set, view.depth[i], p);
      bool r = ch.layer[0] >= 0;
      for (int l : ch.layer)
        if (l >= 0 && r) r = layer_resolves(set, l, p, 3 + c.radius);
      resolved.push_back(r);
    }
    if (!resolved[0]) continue;
    const double single = results[0].visibility.data[i];
    for (size_t l = 0; l < sets.size(); ++l) {
      if (!resolved[l]) continue;
      const double got = results[l].visibility.data[i];
      ++(truth ? lit : dark)[l];
      ASSERT_NEAR(got, single, c.tolerance) << layout_name(all_layouts()[l]) << " receiver " << i;
      ASSERT_NEAR(got, truth, c.tolerance) << layout_name(all_layouts()[l]) << " receiver " << i;
    }
  }
  for (size_t l = 0; l < sets.size(); ++l) {
    // Both kinds in numbers, in every layout (192x108 receivers, the box's shadow in the view).
    EXPECT_GT(lit[l], 1000u) << layout_name(all_layouts()[l]);
    EXPECT_GT(dark[l], 50u) << layout_name(all_layouts()[l]);
  }
  // The layered layouts read every layer somewhere, and blend at their splits.
  for (size_t l : {1, 3}) {
    EXPECT_GT(results[l].blended, 0u) << layout_name(all_layouts()[l]);
    for (size_t k = 0; k < results[l].per_layer.size(); ++k) EXPECT_GT(results[l].per_layer[k], 0u) << k;
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, LayeredScene,
                         ::testing::Values(SceneCase{"sm", 0, 1e-6}, SceneCase{"pcf", 1, 1e-6},
                                           SceneCase{"esm", 2, 5e-3}),
                         [](const auto& info) { return std::string(info.param.method); });

// ---- (b) the projection kernel against select_cascade and layer_footprint -------------------

// Distance of a receiver to the rule's decision boundaries, in double: relative to the depth, to
// every split and band start; in map units, to every layer's map edges. Float and double may
// decide differently only within ~1e-6 of one.
double boundary_margin(const CascadeSet& set, double depth, const Point3& p) {
  double m = kInf;
  for (const CascadeLayer& l : set.layers) {
    const double band_start = l.split_far - set.blend * (l.split_far - l.split_near);
    for (double s : {l.split_near, l.split_far, band_start}) m = std::min(m, std::abs(depth - s) / std::abs(s));
    const LayerTransform::MapPoint q = l.transform.apply(p);
    for (double e : {q.u, 1.0 - q.u, q.v, 1.0 - q.v}) m = std::min(m, std::abs(e));
  }
  return m;
}

TEST(Layered, ProjectionKernelChoosesAsSelectCascade) {
  for (LayoutKind kind : {LayoutKind::Pssm, LayoutKind::PssmTsm}) {
    const CascadeSet set = layout(kind, 64, 0.25);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> x(-14, 14), y(-1, 4), z(-22, 10), depth(0.5f, 27.0f), off(-0.05f, 0.05f);
    ViewReceivers view;
    view.width = 64;
    view.height = 64;
    std::vector<float>* all[] = {&view.x,   &view.y,   &view.z,   &view.depth, &view.dxx,
                                 &view.dxy, &view.dxz, &view.dyx, &view.dyy,   &view.dyz};
    for (size_t i = 0; i < view.count(); ++i) {
      view.x.push_back(x(rng)), view.y.push_back(y(rng)), view.z.push_back(z(rng));
      view.depth.push_back(i % 50 == 0 ? kNaN : depth(rng));
      for (int n = 4; n < 10; ++n) all[n]->push_back(off(rng));
    }
    // Receivers at the camera's own depth: on the layer whose split holds them, where most blend.
    for (size_t i = 1; i < view.count(); i += 3) {
      const Point3 p = position(view, i);
      view.depth[i] = float(dot((p - scene().camera.position), scene().camera.forward));
    }
    FilterOptions opt;
    opt.lookup.kind = Lookup::Mips;  // anisotropic: the projection writes the Jacobians too
    LayeredPipeline pipe(runtime_ptr(), opt, set);
    run(pipe, render_maps(set), view);
    const ref::CascadeProjection got = read_projection(pipe, view);
    ASSERT_TRUE(got.layers[0].has_jacobian);
    size_t near_boundary = 0, blended = 0, none = 0, fell_through = 0;
    for (size_t i = 0; i < view.count(); ++i) {
      const Point3 p = position(view, i);
      const CascadeChoice want = select_cascade(set, view.depth[i], p);
      const CascadeChoice& c = got.choice[i];
      if (c.layer[0] != want.layer[0] || c.layer[1] != want.layer[1]) {
        ASSERT_LT(boundary_margin(set, view.depth[i], p), 1e-5) << layout_name(kind) << " receiver " << i;
        ++near_boundary;
        continue;
      }
      blended += want.layer[1] >= 0;
      none += want.layer[0] < 0;
      fell_through += want.layer[0] > 0 && view.depth[i] < set.layers[want.layer[0]].split_near;
      ASSERT_NEAR(c.weight[1], want.weight[1], 1e-5) << i;
      for (int k = 0; k < int(set.layers.size()); ++k) {
        const Receivers& rx = got.layers[k];
        if (k != want.layer[0] && k != want.layer[1]) {
          ASSERT_TRUE(std::isnan(rx.d[i]) && rx.u[i] == 0.0f && rx.v[i] == 0.0f && rx.f[i] == 1.0f) << k << " " << i;
          ASSERT_TRUE(rx.dudx[i] == 1.0f && rx.dvdx[i] == 0.0f && rx.dudy[i] == 0.0f && rx.dvdy[i] == 1.0f) << k;
          continue;
        }
        const LayerTransform::MapPoint q = set.layers[k].transform.apply(p);
        const Point3 dx{view.dxx[i], view.dxy[i], view.dxz[i]}, dy{view.dyx[i], view.dyy[i], view.dyz[i]};
        const double f = layer_footprint(set, k, p, dx, dy);
        ASSERT_NEAR(rx.u[i], q.u, 1e-5) << k << " " << i;
        ASSERT_NEAR(rx.v[i], q.v, 1e-5) << k << " " << i;
        ASSERT_NEAR(rx.d[i], q.d, 1e-5) << k << " " << i;
        ASSERT_NEAR(rx.f[i], f, 1e-4 * std::max(1.0, f)) << k << " " << i;
        const std::array<double, 4> jac = layer_jacobian(set, k, p, dx, dy);
        const float got_jac[4] = {rx.dudx[i], rx.dvdx[i], rx.dudy[i], rx.dvdy[i]};
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(got_jac[c], jac[size_t(c)], 1e-4 * std::max(1.0, f)) << k << " " << i;
      }
    }
    // The random receivers reach every branch of the rule.
    EXPECT_LE(near_boundary, view.count() / 200) << layout_name(kind);
    EXPECT_GT(blended, 20u) << layout_name(kind);
    EXPECT_GT(none, 200u) << layout_name(kind);
    EXPECT_GT(fell_through, 5u) << layout_name(kind);
  }
}

// The normal offset in the projection (sf_cascade_moved): each served layer reads the receiver
// moved 1.5 of its texels along the camera-facing normal of the pixel's offsets, as the double
// twin moves it; on the scene's view, receivers facing the light (ndl > 0.1) move towards it
// (d falls) in every layer that serves them, so the normal's orientation is the camera's side.
TEST(Layered, ProjectionMovesReceiversAlongTheirNormals) {
  const CascadeSet set = layout(LayoutKind::PssmTsm, 96, 0.2);
  const ViewReceivers view = render_view(128, 72);
  FilterOptions opt;
  opt.method = "sm";
  opt.normal_offset = 1.5f;
  LayeredPipeline pipe(runtime_ptr(), opt, set);
  run(pipe, render_maps(set), view);
  const ref::CascadeProjection got = read_projection(pipe, view);
  const ref::CascadeProjection want = ref::project_cascades(set, view, 1.5);
  const ref::CascadeProjection still = ref::project_cascades(set, view);
  size_t compared = 0, towards_light = 0, facing = 0;
  for (size_t i = 0; i < view.count(); ++i) {
    if (got.choice[i].layer[0] != want.choice[i].layer[0] || got.choice[i].layer[1] != want.choice[i].layer[1])
      continue;  // a float / double decision at a boundary (ProjectionKernelChoosesAsSelectCascade)
    for (int k = 0; k < int(set.layers.size()); ++k) {
      if (!std::isfinite(want.layers[k].d[i])) continue;
      ASSERT_NEAR(got.layers[k].u[i], want.layers[k].u[i], 2e-5) << k << " " << i;
      ASSERT_NEAR(got.layers[k].v[i], want.layers[k].v[i], 2e-5) << k << " " << i;
      ASSERT_NEAR(got.layers[k].d[i], want.layers[k].d[i], 2e-5) << k << " " << i;
      ++compared;
      if (view.ndl[i] > 0.1f) {
        ++facing;
        towards_light += want.layers[k].d[i] < still.layers[k].d[i];
      }
    }
  }
  EXPECT_GT(compared, view.count() / 2);
  EXPECT_GT(facing, 1000u);
  EXPECT_EQ(towards_light, facing);
}

// One receivers type and one stage-times type: the layered pipeline reads the view part of
// DeviceReceivers (a map part alone is refused, naming the field), and its times are its layers'
// summed stage by stage plus the projection and the blend.
TEST(Layered, ReadsTheViewPartAndSumsItsLayersTimes) {
  const CascadeSet set = layout(LayoutKind::Pssm, 64);
  LayeredPipeline pipe(runtime_ptr(), FilterOptions{}, set);
  const ViewReceivers view = render_view(32, 18);
  run(pipe, render_maps(set), view);
  const StageTimes t = pipe.times();
  double layers = 0;
  for (int k = 0; k < pipe.layer_count(); ++k) layers += pipe.layer(k).times().total();
  EXPECT_NEAR(t.total(), layers + t.project + t.blend, 1e-12);
  if (test::runtime().profiling()) {
    EXPECT_GT(t.project, 0.0);
  }

  DeviceReceivers map_only;
  map_only.count = view.count();
  map_only.u = map_only.v = map_only.d = test::to_device(std::vector<float>(view.count(), 0.5f));
  const cl::Buffer vis = test::to_device(std::vector<float>(view.count(), -1.0f));
  try {
    pipe.reconstruct(map_only, vis);
    FAIL() << "receivers without a view part must be refused";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "DeviceReceivers::view.x is an empty buffer");
  }
}

// ---- (c) warped layers: world -> map -> world ----------------------------------------------

TEST(Layered, WarpedLayersRoundTripBetweenWorldAndMap) {
  for (LayoutKind kind : {LayoutKind::Tsm, LayoutKind::PssmTsm}) {
    const CascadeSet set = layout(kind, 64);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit01(0.01, 0.99);
    for (size_t k = 0; k < set.layers.size(); ++k) {
      const CascadeLayer& layer = set.layers[k];
      // Host, in double: map -> world -> map, and the world point back.
      ViewReceivers view;
      view.width = 32;
      view.height = 16;
      std::vector<Point3> points;
      for (size_t i = 0; i < view.count(); ++i) {
        const double u = unit01(rng), v = unit01(rng), d = unit01(rng);
        Point3 p, p2;
        ASSERT_TRUE(layer.transform.unproject(u, v, d, p));
        const LayerTransform::MapPoint q = layer.transform.apply(p);
        ASSERT_GT(q.w, 0.0);
        ASSERT_NEAR(q.u, u, 1e-9);
        ASSERT_NEAR(q.v, v, 1e-9);
        ASSERT_NEAR(q.d, d, 1e-9);
        ASSERT_TRUE(layer.transform.unproject(q.u, q.v, q.d, p2));
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(p2[a], p[a], 1e-5) << layout_name(kind) << " layer " << k;
        points.push_back(p);
        view.x.push_back(float(p[0])), view.y.push_back(float(p[1])), view.z.push_back(float(p[2]));
        // A view depth in the middle of the layer's split range, before its blend band.
        view.depth.push_back(float(layer.split_near + 0.3 * (layer.split_far - layer.split_near)));
        for (auto* a : {&view.dxx, &view.dxy, &view.dxz, &view.dyx, &view.dyy, &view.dyz}) a->push_back(0.01f);
      }
      // Device: the kernel's (u, v, d) of the float world point, unprojected in double, is the
      // point within what float inputs allow (1e-5 in map units is 1e-3 texels of a 64 map).
      LayeredPipeline pipe(runtime_ptr(), FilterOptions{}, set);
      run(pipe, render_maps(set), view);
      const ref::CascadeProjection got = read_projection(pipe, view);
      for (size_t i = 0; i < view.count(); ++i) {
        ASSERT_EQ(got.choice[i].layer[0], int(k)) << i;
        const Point3 pf{view.x[i], view.y[i], view.z[i]};
        const LayerTransform::MapPoint q = layer.transform.apply(pf);
        const Receivers& rx = got.layers[k];
        ASSERT_NEAR(rx.u[i], q.u, 1e-5);
        ASSERT_NEAR(rx.v[i], q.v, 1e-5);
        ASSERT_NEAR(rx.d[i], q.d, 1e-5);
        Point3 back;
        ASSERT_TRUE(layer.transform.unproject(rx.u[i], rx.v[i], rx.d[i], back));
        const double texel = layer_texel_size(set, int(k), pf);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(back[a], pf[a], 1e-3 * texel) << layout_name(kind) << " " << i;
      }
    }
  }
}

// ---- (d) each layer filtered alone, with its own blur ----------------------------------------

TEST(Layered, LayerBlurKeepsLayerZerosWorldWidth) {
  const CascadeSet set = layout(LayoutKind::Pssm, 64);
  FilterOptions opt;
  opt.blur.radius = 6;
  const double t0 = layer_reference_texel(set, 0);
  int narrower = 0;
  for (int k = 0; k < int(set.layers.size()); ++k) {
    const double s = t0 / layer_reference_texel(set, k);
    const FilterOptions o = layer_filter_options(opt, set, k);
    const int want = 6 * s < 1.0 ? 0 : int(std::lround(6 * s));
    EXPECT_EQ(o.blur.radius, want) << k;
    const float sigma = o.blur.sigma > 0.0f ? o.blur.sigma : default_blur_sigma(o.blur.radius);
    if (want > 0) {
      EXPECT_NEAR(sigma, default_blur_sigma(6) * s, 1e-6) << k;
    }
    narrower += want < 6;
  }
  EXPECT_GT(narrower, 0);  // pssm's far layers have coarser texels
  opt.blur.radius = 1;     // under one texel of the far layers: no blur there
  EXPECT_EQ(layer_filter_options(opt, set, 2).blur.radius, 0);
}

// The basis and the mip chain each layer's pipeline holds are the reference's of that layer's
// map alone: layers of distinct depths, so a filter that read across layers would show at their
// borders (the blur's clamp-to-edge, the pyramid's last texels).
TEST(Layered, EachLayerIsFilteredAlone) {
  const CascadeSet set = layout(LayoutKind::Pssm, 64);
  std::vector<HostImage> maps;
  for (int k = 0; k < 3; ++k) maps.push_back(test::random_depth(64, 64, 40 + k, 0.1f + 0.3f * k, 0.3f + 0.3f * k));
  for (const char* method : {"esm", "vsm"}) {
    FilterOptions opt;
    opt.method = method;
    opt.esm.c = 40;
    opt.blur.radius = 5;
    opt.lookup.kind = Lookup::Mips;
    LayeredPipeline pipe(runtime_ptr(), opt, set);
    std::vector<cl::Buffer> depth;
    for (const HostImage& m : maps) depth.push_back(test::to_device(m.data));
    pipe.prefilter(depth).wait();
    for (int k = 0; k < 3; ++k) {
      const FilterOptions o = layer_filter_options(opt, set, k);
      ref::Planes want = ref::transform(o, maps[k]);
      if (o.blur.radius > 0) want = ref::blur(want, o.blur.radius, o.blur.sigma);
      const ImageShape shape = pipe.layer(k).basis_shape();
      const std::vector<float> got = test::from_device(pipe.layer(k).basis(), shape.plane_texels() * shape.channels);
      for (size_t j = 0; j < got.size(); ++j)
        ASSERT_NEAR(got[j], want.data[j], 1e-5 * std::max(1.0, std::abs(want.data[j])))
            << method << " layer " << k << " value " << j;
      const std::vector<ref::Planes> chain = ref::mip_chain(want, 0);
      const MipLayout mips = mip_layout(shape.width, shape.height, shape.channels);
      const std::vector<float> levels = test::from_device(pipe.layer(k).lookup_tables().chain, mips.chain_values);
      for (int l = 1; l <= mips.top(); ++l)
        for (size_t j = 0; j < chain[l].data.size(); ++j)
          ASSERT_NEAR(levels[mips.levels[l].offset + j], chain[l].data[j],
                      1e-5 * std::max(1.0, std::abs(chain[l].data[j])))
              << method << " layer " << k << " level " << l;
    }
  }
}

// ---- (d') the soft methods per layer (layer_soft_light) ---------------------------------------

// A plane for the area light 4 world units before the nearest d = 0 plane of the sets' layers.
double soft_light_plane(const std::vector<const CascadeSet*>& sets) {
  double near = kInf;
  for (const CascadeSet* set : sets)
    for (int k = 0; k < int(set->layers.size()); ++k)
      near = std::min(near, layer_soft_light(*set, k, 1, 1, 0).near_plane);
  return near - 4.0;
}

Point3 matrix_row(const CascadeSet& set, int k, int r) {
  const auto& m = set.layers[k].transform.m;
  return {m[4 * r], m[4 * r + 1], m[4 * r + 2]};
}

// Every layer's light is the one world light: its planes from the layer's d row, its place from
// the light's plane, and a blocker 1 unit before a receiver 6 units past the light's plane casts
// a footprint of size / 6 x height / 6 world units in every layer (the texels differ). Warped
// and skewed layers are refused.
TEST(LayeredSoft, EveryLayersLightIsTheWorldLight) {
  const CascadeSet set = layout(LayoutKind::Pssm, 128);
  const double plane = soft_light_plane({&set});
  for (int k = 0; k < int(set.layers.size()); ++k) {
    const SoftLight L = layer_soft_light(set, k, 1.5, 1.0, plane);
    const double su = length(matrix_row(set, k, 0)), sv = length(matrix_row(set, k, 1));
    const double sd = length(matrix_row(set, k, 2));
    EXPECT_FALSE(L.perspective);
    EXPECT_NEAR(L.extent, 1.0 / su, 1e-9);
    EXPECT_NEAR(L.near_plane, -set.layers[k].transform.m[11] / sd, 1e-9);
    EXPECT_NEAR(L.far_plane - L.near_plane, 1.0 / sd, 1e-9);
    EXPECT_NEAR(L.light_distance, L.near_plane - plane, 1e-9);
    EXPECT_GT(L.light_distance, 3.99) << k;
    const auto d_of = [&](double D) { return (plane + D - L.near_plane) / (L.far_plane - L.near_plane); };
    EXPECT_NEAR(soft_width(L, d_of(6.0), d_of(5.0)) / su, 1.5 / 6.0, 1e-9) << k;
    EXPECT_NEAR(soft_height(L, d_of(6.0), d_of(5.0)) / sv, 1.0 / 6.0, 1e-9) << k;
    EXPECT_EQ(soft_width(L, d_of(5.0), d_of(6.0)), 0.0);  // the blocker behind the receiver
  }
  const CascadeSet tsm = layout(LayoutKind::Tsm, 64);
  SoftOptions o;
  EXPECT_THROW(LayeredPipeline(runtime_ptr(), o, tsm, plane), InputError);
  try {
    layer_soft_light(tsm, 0, 1, 1, plane);
    ADD_FAILURE() << "a warped layer was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("warped"), std::string::npos) << e.what();
  }
  CascadeSet skewed = set;
  for (int e = 0; e < 3; ++e) skewed.layers[1].transform.m[e] += 0.3 * skewed.layers[1].transform.m[8 + e];
  EXPECT_THROW(layer_soft_light(skewed, 1, 1, 1, plane), InputError);
  EXPECT_NO_THROW(layer_soft_light(skewed, 0, 1, 1, plane));
  EXPECT_THROW(layer_soft_light(set, 0, 1, 1, NAN), InputError);
}

// The ray-traced soft shadow of the scene's box under a W x H light in the plane `plane` along
// the light's axis, its sides along the layers' u and v (8 x 8 stratified samples; the light
// moves with the receiver, as the ortho light of `scene` does).
std::vector<double> traced_soft(const ViewReceivers& view, const CascadeSet& set, double plane, double W, double H) {
  const Point3 right = normalize(matrix_row(set, 0, 0)), down = normalize(matrix_row(set, 0, 1));
  const Point3 axis = normalize(matrix_row(set, 0, 2));
  std::vector<double> out(view.count(), NAN);
  for (size_t i = 0; i < view.count(); ++i) {
    if (!std::isfinite(view.depth[i])) continue;
    const Point3 p = position(view, i);
    const Point3 base = (p - ((dot(axis, p) - plane) * axis));
    int lit = 0;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const Point3 q = (base + ((((a + 0.5) / 8 - 0.5) * W) * right + (((b + 0.5) / 8 - 0.5) * H) * down));
        const Point3 o = (p + (1e-6 * (q - p)));
        lit += !(hit_box(scene().occluder, o, (q - p)).t < 1.0);
      }
    out[i] = lit / 64.0;
  }
  return out;
}

// Each soft method per layer of pssm (3 x 160²) and of the single map (320², more texels) under
// one 2 x 1.2 light, against the ray-traced area light over the receivers that face the light
// and that both serve: pssm's finer near layers may not be worse, and each stays within its bound
// (measured RMSE single / pssm: pcss 0.028 / 0.021, cssm 0.043 / 0.045, ssmm 0.033 / 0.023,
// ssmm-improved 0.036 / 0.030). With every layer's light at its own d = 0 plane instead of the
// world light's plane, pcss and ssmm on pssm measured 0.042 and 0.041: past their 0.03.
TEST(LayeredSoft, EveryMethodAgainstTheRayTracedAreaLight) {
  const ViewReceivers view = render_view(192, 108);
  const CascadeSet single = layout(LayoutKind::Single, 2 * kMapSize), pssm = layout(LayoutKind::Pssm, kMapSize);
  const std::vector<HostImage> single_maps = render_maps(single), pssm_maps = render_maps(pssm);
  // The light 3 units before the box's top. The far ground lies before the light's plane, outside
  // the model (SoftLight::light_distance), and is not counted.
  const Point3 axis = normalize(matrix_row(single, 0, 2));
  const double plane = dot(axis, Point3{0, 2, 0}) - 3.0, W = 2.0, H = 1.2;
  const std::vector<double> want = traced_soft(view, single, plane, W, H);
  std::vector<uint8_t> mask(view.count(), 0);
  size_t counted = 0, penumbra = 0;
  for (size_t i = 0; i < view.count(); ++i) {
    if (!std::isfinite(view.depth[i]) || !(view.ndl[i] > 0.0f)) continue;
    const Point3 p = position(view, i);
    if (!(dot(axis, p) > plane + 0.5)) continue;
    if (select_cascade(single, view.depth[i], p).layer[0] < 0 || select_cascade(pssm, view.depth[i], p).layer[0] < 0)
      continue;
    mask[i] = 1;
    ++counted;
    penumbra += want[i] > 0.02 && want[i] < 0.98;
  }
  ASSERT_GT(counted, 10000u);
  ASSERT_GT(penumbra, 300u) << "the light must cast penumbrae the test can see";
  for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}) {
    SoftOptions o;
    o.method = m;
    o.light.size = W;
    o.light.height = H;
    const auto rmse = [&](const CascadeSet& set, const std::vector<HostImage>& maps) {
      const LayeredResult r = filter_layered(runtime_ptr(), o, set, plane, maps, view);
      double sum = 0;
      for (size_t i = 0; i < view.count(); ++i) {
        if (!mask[i]) continue;
        EXPECT_TRUE(std::isfinite(r.visibility.data[i])) << i;
        sum += (r.visibility.data[i] - want[i]) * (r.visibility.data[i] - want[i]);
      }
      return std::sqrt(sum / counted);
    };
    const double e_single = rmse(single, single_maps), e_pssm = rmse(pssm, pssm_maps);
    std::printf("  %s: RMSE single %.4f, pssm3 %.4f over %zu receivers (%zu in penumbrae)\n", soft_method_name(m),
                e_single, e_pssm, counted, penumbra);
    EXPECT_LE(e_pssm, e_single * 1.05 + 1e-3) << soft_method_name(m);
    EXPECT_LT(e_single, 0.05) << soft_method_name(m);
    EXPECT_LT(e_pssm, m == SoftMethod::Cssm           ? 0.05
                      : m == SoftMethod::SsmmImproved ? 0.035
                                                      : 0.03)
        << soft_method_name(m);
  }
}

// ---- (e) the layered pipeline against the layered reference ---------------------------------

struct RefCase {
  const char* method;
  Lookup lookup;
  int radius;
  double tolerance;  // kernel against the reference on the kernel's projection
};

class LayeredReference : public ::testing::TestWithParam<RefCase> {};

// Against the reference from the kernel's own projection: the filtering alone, to the per-map
// tolerances of tests/core/test_methods.cpp (sm, pcf 1e-5; esm 2e-5 + 1e-7 c; vsm 6e-3, Chebyshev's
// conditioning). Against the whole double reference (its own projection in double): the float
// projection moves u, v, d by ~1e-7, which a depth test at its threshold or ESM's exponential
// can turn into more; stated as a bound on the worst receiver after the 0.1% nearest to such a
// threshold.
TEST_P(LayeredReference, MatchesTheReference) {
  const RefCase& c = GetParam();
  const CascadeSet set = layout(LayoutKind::PssmTsm, 96, 0.2);
  const std::vector<HostImage> maps = render_maps(set);
  const ViewReceivers view = render_view(128, 72);
  FilterOptions opt;
  opt.method = c.method;
  opt.lookup.kind = c.lookup;
  opt.blur.radius = c.radius;
  opt.esm.c = 60;
  opt.esm_classify.mode = EsmClassify::None;  // the reference has no classification stage
  opt.facing_away_shadowed = false;           // a device pipeline leaves n.l to its caller
  LayeredPipeline pipe(runtime_ptr(), opt, set);
  const std::vector<float> got = run(pipe, maps, view);
  const std::vector<double> exact = ref::filter_cascades(opt, set, maps, read_projection(pipe, view));
  for (size_t i = 0; i < got.size(); ++i) ASSERT_NEAR(got[i], exact[i], c.tolerance) << c.method << " receiver " << i;

  const std::vector<double> full = ref::filter_cascades(opt, set, maps, view);  // facing away: off above
  std::vector<double> err;
  for (size_t i = 0; i < got.size(); ++i) err.push_back(std::abs(got[i] - full[i]));
  std::sort(err.begin(), err.end());
  EXPECT_LE(err[err.size() - 1 - err.size() / 1000], 2e-3) << c.method;
  const double shadowed = std::count_if(got.begin(), got.end(), [](float v) { return v < 0.5f; });
  EXPECT_GT(shadowed, 100) << "the view must hold shadow to test anything";
}

INSTANTIATE_TEST_SUITE_P(Methods, LayeredReference,
                         ::testing::Values(RefCase{"sm", Lookup::Bilinear, 0, 1e-5},
                                           RefCase{"pcf", Lookup::Mips, 1, 1e-5},
                                           RefCase{"esm", Lookup::Mips, 3, 2e-5 + 1e-7 * 60},
                                           RefCase{"vsm", Lookup::Sat, 2, 6e-3}),
                         [](const auto& info) { return std::string(info.param.method); });

// ---- (f) the command ------------------------------------------------------------------------

struct CliFiles {
  std::string dir;
  std::vector<std::string> layers;
  std::string view;
};

// A small cascade set on disk, each layer changed by `edit` before it is written.
CliFiles write_cascades(const std::string& name, const std::function<void(int, HostImage&)>& edit = {}) {
  CliFiles f;
  f.dir = test::temp_dir(name);
  const CascadeSet set = layout(LayoutKind::Pssm, 64);
  const std::vector<HostImage> maps = render_maps(set);
  for (int k = 0; k < int(maps.size()); ++k) {
    HostImage m = maps[k];
    m.attributes = io::cascade_layer_attributes(set, k);
    if (edit) edit(k, m);
    f.layers.push_back(f.dir + "/cascade_" + std::to_string(k) + ".exr");
    io::write_image(f.layers.back(), m);
  }
  const ViewReceivers v = render_view(48, 27);
  HostImage view(v.width, v.height, 11);
  view.channel_names = io::view_channel_names();
  const std::vector<float>* ch[] = {&v.x, &v.y, &v.z, &v.depth, &v.dxx, &v.dxy, &v.dxz, &v.dyx, &v.dyy, &v.dyz, &v.ndl};
  for (size_t i = 0; i < v.count(); ++i)
    for (int c = 0; c < 11; ++c) view.data[i * 11 + c] = (*ch[c])[i];
  f.view = f.dir + "/view.exr";
  io::write_image(f.view, view);
  return f;
}

void replace_matrix_entry(HostImage& m, double value) {
  std::string& text = m.attributes["shadowfilter:world_to_map"];
  text = std::to_string(value) + text.substr(text.find(' '));
}

TEST(LayeredCli, FiltersADirectoryOfLayers) {
  const CliFiles f = write_cascades("layered_cli_ok");
  const std::string out = f.dir + "/vis.exr";
  const auto r = test::run_cli("filter --cascades " + f.dir + " --view " + f.view + " -o " + out +
                                   " --method pcf --blur-radius 1 --cascade-blend 0.2 --preview",
                               f.dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3 layers of 64x64, blend 0.2"), std::string::npos) << r.out;
  const HostImage vis = io::load_depth_map(out, io::DepthLoadOptions{});
  EXPECT_EQ(vis.width, 48);
  EXPECT_EQ(vis.height, 27);
  EXPECT_TRUE(std::filesystem::exists(f.dir + "/vis.png"));
  // A list of files is the same set.
  const auto list = test::run_cli("filter --cascades " + f.layers[0] + "," + f.layers[1] + "," + f.layers[2] +
                                      " --view " + f.view + " -o " + f.dir + "/list.exr -q",
                                  f.dir);
  EXPECT_EQ(list.exit_code, 0) << list.err;
}

struct BadCase {
  const char* name;
  std::function<void(int, HostImage&)> edit;  // on the layer files
  std::string args;                           // extra arguments; VIEW names the view file
  const char* message;                        // part of the one error line
};

TEST(LayeredCli, BadInputExitsTwoAndWritesNothing) {
  const auto layer = [](int which, std::function<void(HostImage&)> f) {
    return [which, f](int k, HostImage& m) {
      if (k == which) f(m);
    };
  };
  const std::vector<BadCase> cases = {
      {"size",
       layer(2,
             [](HostImage& m) {
               auto a = m.attributes;
               m = HostImage(32, 64, 1, 1.0f);
               m.attributes = a;
             }),
       "", "differs from layer 0's"},
      {"order", layer(1, [](HostImage& m) { m.attributes["shadowfilter:split"] = "9 3"; }), "", "must increase"},
      {"gap", layer(2, [](HostImage& m) { m.attributes["shadowfilter:split"] = "14 25"; }), "", "without gaps"},
      {"singular",
       layer(0, [](HostImage& m) { m.attributes["shadowfilter:world_to_map"] = "0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1"; }),
       "", "singular"},
      {"attribute", layer(1, [](HostImage& m) { m.attributes.erase("shadowfilter:blend"); }), "", "shadowfilter:blend"},
      {"nonfinite", layer(0, [](HostImage& m) { replace_matrix_entry(m, kInf); }), "", "world_to_map"},
      {"blend", {}, "--cascade-blend 1.5", "--cascade-blend"},
      {"shadow-map", {}, "--shadow-map VIEW", "--shadow-map"},
      {"receivers", {}, "--receivers VIEW", "--receivers"},
      {"view", {}, "NOVIEW", "has no channel dPdy.z"},
  };
  for (const BadCase& c : cases) {
    const CliFiles f = write_cascades(std::string("layered_cli_") + c.name, c.edit);
    std::string view = f.view;
    std::string args = c.args;
    if (args == "NOVIEW") {  // a view file without one of its channels
      HostImage partial(48, 27, 10);
      partial.channel_names = io::view_channel_names();
      partial.channel_names.resize(10);
      partial.channel_names.back() = "other";
      view = f.dir + "/partial.exr";
      io::write_image(view, partial);
      args.clear();
    }
    const size_t at = args.find("VIEW");
    if (at != std::string::npos) args.replace(at, 4, f.view);
    const std::string out = f.dir + "/vis.exr";
    const auto r =
        test::run_cli("filter --cascades " + f.dir + " --view " + view + " -o " + out + " --preview " + args, f.dir);
    EXPECT_EQ(r.exit_code, 2) << c.name << ": " << r.err;
    EXPECT_EQ(test::count_lines(r.err), 1u) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.name;
    EXPECT_FALSE(std::filesystem::exists(f.dir + "/vis.png")) << c.name;
  }
}

}  // namespace
}  // namespace sf

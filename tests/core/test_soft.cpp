// Soft shadows (kernels/soft/*.cl, host/src/soft/soft_filter.cpp; docs/soft.md): kernels against the
// scalar reference, cssm's average blocker depth against the brute-force mean, and the
// parallel-planes penumbra width of every method.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include "image_io.hpp"
#include "lookups.hpp"
#include "scene_generate.hpp"
#include "scene_render.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/footprint.hpp"
#include "shadowfilter/soft.hpp"
#include "soft_reference.hpp"

namespace sf::test {
namespace {

using namespace sf::scene;

Receivers receivers_of(const HostImage& rx) {
  Receivers r;
  r.width = rx.width;
  r.height = rx.height;
  r.has_footprint = rx.channels >= 4;
  for (size_t i = 0; i < rx.texels(); ++i) {
    r.u.push_back(rx.data[i * rx.channels + 0]);
    r.v.push_back(rx.data[i * rx.channels + 1]);
    r.d.push_back(rx.data[i * rx.channels + 2]);
    r.f.push_back(r.has_footprint ? rx.data[i * rx.channels + 3] : 1.0f);
  }
  return r;
}

ref::Planes planes_of(const HostImage& img) {
  ref::Planes p(img.width, img.height, 1);
  for (size_t i = 0; i < img.texels(); ++i) p.data[i] = img.data[i];
  return p;
}

// Floor at z = 0.8 with rectangular occluders at 0.2..0.6 (64 x 64): blockers at several depths.
HostImage blocky_map(int n) {
  HostImage m(n, n, 1, 0.8f);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pos(0, n - 1), len(2, n / 4);
  std::uniform_real_distribution<float> z(0.2f, 0.6f);
  for (int k = 0; k < 12; ++k) {
    const int x0 = pos(rng), y0 = pos(rng), w = len(rng), h = len(rng);
    const float zz = z(rng);
    for (int y = y0; y < std::min(n, y0 + h); ++y)
      for (int x = x0; x < std::min(n, x0 + w); ++x) m.at(x, y) = std::min(m.at(x, y), zz);
  }
  return m;
}

SoftOptions ortho_options(SoftMethod m, double size, double extent) {
  SoftOptions o;
  o.method = m;
  o.light.size = size;
  o.light.extent = extent;
  return o;
}

std::vector<float> run_device(const SoftOptions& o, const HostImage& depth, const Receivers& rx,
                              std::vector<float>* zavg = nullptr) {
  SoftFilter f(runtime_ptr(), o, depth.width, depth.height);
  cl::Buffer dz = to_device(depth.data), u = to_device(rx.u), v = to_device(rx.v), d = to_device(rx.d);
  cl::Buffer fp = rx.has_footprint ? to_device(rx.f) : cl::Buffer();
  std::vector<float> jac;  // the Jacobian's four planes (DeviceReceivers::jacobian)
  if (rx.has_jacobian) jacobian_planes(rx, jac);
  cl::Buffer out = to_device(std::vector<float>(rx.d.size(), -1.0f));
  cl::Buffer za = to_device(std::vector<float>(rx.d.size(), 0.0f));
  cl::Event e = f.prefilter(dz);
  EventList after{e};
  DeviceReceivers points{false, rx.d.size(), u, v, d, fp};
  if (rx.has_jacobian) points.jacobian = to_device(jac);
  if (zavg)
    f.reconstruct(points, out, za, &after);
  else
    f.reconstruct(points, out, &after);
  if (zavg) *zavg = from_device(za, rx.d.size());
  return from_device(out, rx.d.size());
}

// --- kernels against the scalar reference --------------------------------------------------
struct RefCase {
  SoftMethod method;
  Lookup lookup;
  int order;
  bool perspective = false;
  Storage storage = Storage::F32;   // cssm's basis (mips only)
  double width = 0.1, height = -1;  // the light's sides (map widths; height < 0: a square)
  double light_distance = 0;        // ortho: the light's plane this far before d = 0 (map depths)
  bool jacobian = false;            // receivers with Jacobians (footprint rectangles up to 12 texels)
};

class SoftKernelVsReference : public ::testing::TestWithParam<RefCase> {};

// Receivers at random (u, v) with d on the floor (0.8) or between the occluders; light of 0.1
// map widths (search box ~6 texels) so that every receiver under an edge sees partial shadow.
// Decisions (blocker test, box edges) are float32 in the kernel and double in the reference, so a
// receiver exactly at a threshold may differ: 99.5% of the receivers must agree within 1e-4
// (measured worst: 2.3e-6, cssm M = 16), none may be NaN, and the mean difference stays < 1e-5.
TEST_P(SoftKernelVsReference, AgreesWithDoubleReference) {
  const RefCase c = GetParam();
  const HostImage depth = blocky_map(64);
  Receivers rx;
  rx.width = 1500;
  rx.height = 1;
  rx.has_footprint = true;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f), dd(0.3f, 0.9f), fp(0.5f, 3.0f);
  for (int i = 0; i < rx.width; ++i) {
    rx.u.push_back(uni(rng));
    rx.v.push_back(uni(rng));
    rx.d.push_back(i % 2 ? 0.8f : dd(rng));
    rx.f.push_back(fp(rng));
  }
  rx.d[0] = NAN;     // background
  rx.u[1] = 1.5f;    // outside
  if (c.jacobian) {  // every orientation, ratios up to 10, major sides 0.5 .. 12 texels
    rx.has_jacobian = true;
    std::uniform_real_distribution<float> angle(0.0f, 6.2831853f), major(0.5f, 12.0f), ratio(1.0f, 10.0f);
    for (int i = 0; i < rx.width; ++i) {
      const float m = major(rng), w = m / ratio(rng), t = angle(rng);
      rx.dudx.push_back(m * std::cos(t));
      rx.dvdx.push_back(m * std::sin(t));
      rx.dudy.push_back(-w * std::sin(t));
      rx.dvdy.push_back(w * std::cos(t));
    }
    footprint_from_jacobian(rx);
  }
  SoftOptions o = ortho_options(c.method, c.width, 1.0);
  o.light.height = c.height;
  o.light.light_distance = c.light_distance;
  if (c.perspective) {  // near 2, far 6, 60 degrees: search box 0.1 / (2 tan 30) (D_R - D_B) / (D_R D_B)
    o.light.perspective = true;
    o.light.size = 5 * c.width;
    o.light.height = 5 * c.height;
    o.light.near_plane = 2.0;
    o.light.far_plane = 6.0;
    o.light.fov_degrees = 60.0;
  }
  o.cssm.lookup = c.lookup;
  o.cssm.order = c.order;
  o.cssm.storage = c.storage;
  const std::vector<float> got = run_device(o, depth, rx);
  const ref::Planes P = planes_of(depth);
  std::vector<ref::Planes> chain;
  std::unique_ptr<ref::LookupRef> lk;
  if (c.method == SoftMethod::Ssmm || c.method == SoftMethod::SsmmImproved) chain = ref::mip_chain(P, 2);
  if (c.method == SoftMethod::Cssm)
    lk = std::make_unique<ref::LookupRef>(ref::cssm_basis(depth, c.order, c.storage), c.lookup, c.storage);
  // A narrow basis is quantised alike in both (ref::cssm_basis, LookupRef), but the device rounds
  // float32 sums of stored values where the reference rounds doubles: a storage step (f16: 2^-11
  // relative; unorm16: 2^-16) apart at most per plane, through the series' gain (measured worst
  // 1.8e-3, mean 9.2e-6: f16, M = 4).
  const bool narrow = c.storage != Storage::F32;
  const double tol = narrow ? 2e-3 : 1e-4;
  size_t bad = 0, partial = 0;
  double mean = 0, worst = 0;
  for (int i = 0; i < rx.width; ++i) {
    double want;
    // One row of receivers has no neighbours above or below: the plane's gradient is the depth
    // map's slope, as in the kernel, which run_device gives no receiver row.
    const ref::Plane plane = ref::receiver_plane(depth, rx, i, o.receiver_plane);
    if (c.method == SoftMethod::Pcss)
      want = ref::soft_pcss(P, o, rx.u[i], rx.v[i], plane, ref::soft_footprint(rx, i));
    else if (c.method == SoftMethod::Cssm)
      want = ref::soft_cssm(*lk, depth.width, depth.height, o, rx.u[i], rx.v[i], rx.d[i], ref::soft_footprint(rx, i));
    else
      want = ref::soft_ssmm(chain, o, rx.u[i], rx.v[i], plane, ref::soft_footprint(rx, i));
    ASSERT_TRUE(std::isfinite(got[i])) << i;
    const double e = std::abs(got[i] - want);
    bad += e > tol;
    mean += e / rx.width;
    worst = std::max(worst, e);
    partial += want > 0.02 && want < 0.98;
  }
  EXPECT_EQ(got[0], 1.0f);
  EXPECT_EQ(got[1], 1.0f);
  std::printf("  %s%s, light %g x %g: %zu of %d beyond %.0e (worst %.3g, mean %.2e), %zu partial receivers\n",
              soft_method_name(c.method), c.perspective ? " (perspective)" : "", o.light.size, light_height(o.light),
              bad, rx.width, tol, worst, mean, partial);
  EXPECT_LE(bad, size_t(rx.width / 200));
  EXPECT_LT(mean, narrow ? 3e-5 : 1e-5);
  EXPECT_GT(partial, size_t(50)) << "the case must exercise penumbrae";
}

INSTANTIATE_TEST_SUITE_P(
    Methods, SoftKernelVsReference,
    ::testing::Values(RefCase{SoftMethod::Pcss, Lookup::Sat, 4}, RefCase{SoftMethod::Cssm, Lookup::Sat, 4},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4}, RefCase{SoftMethod::Cssm, Lookup::Sat, 16},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, true}, RefCase{SoftMethod::Cssm, Lookup::Sat, 4, true},
                      RefCase{SoftMethod::Ssmm, Lookup::Sat, 4}, RefCase{SoftMethod::SsmmImproved, Lookup::Sat, 4},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, false, Storage::F16},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, false, Storage::Unorm16},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 16, false, Storage::F16},
                      // Rectangular lights (4:1 and 1:4, 6:1 perspective): the mips' anisotropic probes
                      // along u and along v, the SAT's rectangle, the boxes of pcss and ssmm.
                      RefCase{SoftMethod::Pcss, Lookup::Sat, 4, false, Storage::F32, 0.2, 0.05},
                      RefCase{SoftMethod::Cssm, Lookup::Sat, 4, false, Storage::F32, 0.2, 0.05},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, false, Storage::F32, 0.2, 0.05},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, true, Storage::F32, 0.03, 0.18},
                      RefCase{SoftMethod::Ssmm, Lookup::Sat, 4, false, Storage::F32, 0.05, 0.2},
                      RefCase{SoftMethod::SsmmImproved, Lookup::Sat, 4, false, Storage::F32, 0.2, 0.05},
                      // 12:1, beyond ssmm's anisotropy cap of 8: boxes under n texels across.
                      RefCase{SoftMethod::Ssmm, Lookup::Sat, 4, false, Storage::F32, 0.3, 0.025},
                      // A light half the map's depth range before its plane d = 0 (a cascade
                      // layer's, layer_soft_light): narrower footprints, the horizon's slope.
                      RefCase{SoftMethod::Pcss, Lookup::Sat, 4, false, Storage::F32, 0.15, -1, 0.5},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, false, Storage::F32, 0.15, -1, 0.5},
                      RefCase{SoftMethod::Ssmm, Lookup::Sat, 4, false, Storage::F32, 0.15, -1, 0.5},
                      RefCase{SoftMethod::SsmmImproved, Lookup::Sat, 4, false, Storage::F32, 0.15, -1, 0.5},
                      // Receivers with Jacobians: each footprint the rectangle bounding its pixel.
                      RefCase{SoftMethod::Pcss, Lookup::Sat, 4, false, Storage::F32, 0.1, -1, 0, true},
                      RefCase{SoftMethod::Cssm, Lookup::Sat, 4, false, Storage::F32, 0.1, -1, 0, true},
                      RefCase{SoftMethod::Cssm, Lookup::Mips, 4, false, Storage::F32, 0.1, -1, 0, true},
                      RefCase{SoftMethod::Ssmm, Lookup::Sat, 4, false, Storage::F32, 0.1, -1, 0, true},
                      RefCase{SoftMethod::SsmmImproved, Lookup::Sat, 4, false, Storage::F32, 0.1, -1, 0, true}),
    [](const auto& info) {
      std::string s = soft_method_name(info.param.method);
      std::replace(s.begin(), s.end(), '-', '_');
      if (info.param.method == SoftMethod::Cssm)
        s += std::string(info.param.lookup == Lookup::Sat ? "_sat" : "_mips") + "_M" + std::to_string(info.param.order);
      if (info.param.perspective) s += "_persp";
      if (info.param.storage != Storage::F32) s += std::string("_") + storage_name(info.param.storage);
      if (info.param.light_distance > 0) s += "_behind";
      if (info.param.jacobian) s += "_jacobian";
      if (info.param.height >= 0)
        s += info.param.height > info.param.width       ? "_tall"
             : info.param.width > 8 * info.param.height ? "_wider"
                                                        : "_wide";
      return s;
    });

// --- cssm's average blocker depth (eq. 8.8 / (1 - s_f)) against the brute-force mean ---------
// Same kernel (SAT box of the search width), same test (z < d - z_offset, the receiver depth
// cssm's z_avg series is evaluated at). Over receivers of the bundled scenes whose search box holds >= 20%
// blockers. Errors in normalised depth, reported as a distribution, and relative to the true
// receiver-blocker distance d - z_avg (what sets the penumbra width).
TEST(SoftCssm, AverageBlockerDepthMatchesBruteForce) {
  for (int M : {4, 16}) {
    std::vector<double> rel, absd;
    for (const char* scene : {"spheres", "fence", "backyard", "contact", "thin"}) {
      const std::string dir = data_path(scene);
      const HostImage depth = io::load_depth_map(dir + "/shadowmap.exr", {});
      Receivers rx = io::load_receiver_image(dir + "/receivers.exr");
      // every 7th receiver keeps the test fast
      Receivers sub;
      for (size_t i = 0; i < rx.count(); i += 7) {
        sub.u.push_back(rx.u[i]);
        sub.v.push_back(rx.v[i]);
        sub.d.push_back(rx.d[i]);
        sub.f.push_back(rx.f[i]);
      }
      sub.width = int(sub.d.size());
      sub.height = 1;
      sub.has_footprint = rx.has_footprint;
      const double size = 0.2, extent = 8.56;  // the bundled maps are ~8.5 units wide
      SoftOptions o = ortho_options(SoftMethod::Cssm, size, extent);
      o.cssm.order = M;
      o.cssm.lookup = Lookup::Sat;
      o.bias = 0.0f;
      std::vector<float> zavg;
      run_device(o, depth, sub, &zavg);
      const ref::Planes P = planes_of(depth);
      for (size_t i = 0; i < sub.d.size(); ++i) {
        const double d = sub.d[i];
        if (!std::isfinite(d) || !std::isfinite(zavg[i])) continue;
        const double f = std::isfinite(sub.f[i]) ? sub.f[i] : 1.0;
        const double w = std::clamp(std::max(soft_width(o.light, d, 0.0) * depth.width, f), 1.0, 256.0);
        // cssm's test is z < d - offset (d' = d - offset): the brute force uses the same one.
        const double off = cssm_z_offset(o);
        ref::Plane flat;
        flat.d = d;
        const ref::BoxScan s = ref::box_scan(P.data.data(), P.width, P.height, sub.u[i], sub.v[i], w, w, flat, off);
        if (s.blk < 0.2) continue;
        absd.push_back(std::abs(zavg[i] - s.zavg));
        rel.push_back(std::abs(zavg[i] - s.zavg) / (d - s.zavg));
      }
    }
    ASSERT_GT(rel.size(), 1000u);
    auto pct = [](std::vector<double> v, double p) {
      std::sort(v.begin(), v.end());
      return v[std::min(v.size() - 1, size_t(p * v.size()))];
    };
    std::printf(
        "  cssm M=%d z_avg vs brute force over %zu receivers: |err| median %.4f p90 %.4f p99 %.4f "
        "max %.4f; relative to d - z_avg: median %.3f p90 %.3f p99 %.3f\n",
        M, rel.size(), pct(absd, 0.5), pct(absd, 0.9), pct(absd, 0.99), pct(absd, 1.0), pct(rel, 0.5), pct(rel, 0.9),
        pct(rel, 0.99));
    // Measured (relative; stage 1 at the offset where a lit texel reconstructs to 1): M = 4
    // median 0.004, p90 0.069; M = 16 median 0.013, p90 0.074 (at offset 0.5 / M, where lit texels
    // weigh -0.09: 0.039 / 0.21 and 0.014 / 0.14). A wrong sign or a missing 1/(1 - s_f) gives
    // errors of order 1.
    EXPECT_LT(pct(rel, 0.5), 0.03);
    EXPECT_LT(pct(rel, 0.9), 0.15);
  }
}

// --- parallel planes ---------------------------------------------------------------------------
// A 2 x 2 square occluder 1 unit over the floor, the light 4 units above the floor (as in
// test_scene.cpp). The penumbra (1 / slope of a least-squares line through the 0.1..0.9 ramp of
// floor receivers across the edge x = 1, |z| < 0.6) must be within 10% of L (d_R - d_B) / d_R
// (ortho; docs/scenes.md) or L (d_R - d_B) / d_B (perspective, eq. 2.1), and the umbra (floor
// under the occluder farther than the penumbra from every edge) below 0.05. A rectangular light
// 0.4 x 1.5 (0.4 along the map's u, the world's x) gives the edge the penumbra of L = 0.4: the
// kernels' u side is the scene's right side.
struct PlanesCase {
  bool perspective;
  SoftMethod method;
  Lookup lookup;
  double height = -1;  // the light's v side (its u side: 0.4 when given, else 1.5); < 0: a square
};
class SoftParallelPlanes : public ::testing::TestWithParam<PlanesCase> {};

TEST_P(SoftParallelPlanes, PenumbraWidthAndUmbra) {
  const PlanesCase c = GetParam();
  static std::map<bool, std::pair<HostImage, HostImage>> cache;  // map, receivers per light type
  SceneSetup setup;
  add_floor(setup.geometry, 4.0);
  add_quad(setup.geometry, "occluder", {-1.0, 1.0, -1.0}, {2.0, 0.0, 0.0}, {0.0, 0.0, 2.0});
  const double L = c.height >= 0 ? 0.4 : 1.5;
  if (!c.perspective) {
    setup.light.type = LightType::Ortho;
    setup.light.forward = {0, -1, 0};
    setup.light.right = {1, 0, 0};
    setup.light.down = {0, 0, 1};
    setup.light.right_range = {-4.5, 4.5};
    setup.light.down_range = {-4.5, 4.5};
    setup.light.near_plane = -4.0;
    setup.light.far_plane = 0.1;
  } else {
    // The light 0.16 off the edge's vertical: the edge then falls inside texels of the mip levels
    // cssm's mips read (under the light, u = 0.5 is a texel boundary of every level, where a
    // trilinear lookup ramps over one texel of the level instead of two: -50% penumbra).
    setup.light = LightView::fit_perspective(setup.geometry, {1.16, 4.0, 0.0}, {1.16, 0.0, 0.0}, 120.0, 0.01);
  }
  setup.camera.position = {3.0, 5.0, 0.0};
  setup.camera.target = {1.0, 0.0, 0.0};
  setup.camera.up_hint = {0.0, 0.0, -1.0};
  setup.camera.vertical_fov_degrees = 40.0;
  setup.camera.width = setup.camera.height = 200;
  setup.map_width = setup.map_height = 512;
  setup.samples = 1;
  setup.progress = false;
  if (!cache.count(c.perspective)) {
    const SceneRenderer renderer(setup);
    cache[c.perspective] = {renderer.shadow_map(), renderer.camera_view(false).receivers};
  }
  const HostImage& depth = cache[c.perspective].first;
  const HostImage& rximg = cache[c.perspective].second;
  const Receivers rx = receivers_of(rximg);
  SoftOptions o;
  o.method = c.method;
  o.cssm.lookup = c.lookup;
  o.cssm.order = 16;
  o.light.size = L;
  o.light.height = c.height;
  o.light.perspective = c.perspective;
  o.light.near_plane = setup.light.near_plane;
  o.light.far_plane = setup.light.far_plane;
  o.light.extent = 9.0;
  o.light.fov_degrees = setup.light.fov_degrees;
  const std::vector<float> vis = run_device(o, depth, rx);
  const double d_b = 3.0, d_r = 4.0;
  const double expected = c.perspective ? L * (d_r - d_b) / d_b : L * (d_r - d_b) / d_r;
  // Floor points from the receivers: u, v -> world x, z (ortho: linear; perspective: the light
  // looks straight down from (1.16, 4, 0), so x = 1.16 + (u - 0.5) 2 t 4, t = tan(fov/2)).
  const double t = std::tan(0.5 * setup.light.fov_degrees * M_PI / 180.0);
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  size_t umbra = 0, umbra_bad = 0;
  for (size_t i = 0; i < rx.d.size(); ++i) {
    if (!std::isfinite(rx.d[i])) continue;
    // Floor point from (u, v): the light's own axes (docs/scenes.md).
    const LightView& lv = setup.light;
    const double dist = rx.d[i] * (lv.far_plane - lv.near_plane);  // from the near plane
    double x, z, depth_r;
    if (c.perspective) {
      depth_r = lv.near_plane + dist;  // distance from the light along its axis
      const double a = (2.0 * rx.u[i] - 1.0) * t * depth_r, b = (2.0 * rx.v[i] - 1.0) * t * depth_r;
      x = lv.position.x + depth_r * lv.forward.x + a * lv.right.x + b * lv.down.x;
      z = lv.position.z + depth_r * lv.forward.z + a * lv.right.z + b * lv.down.z;
    } else {
      depth_r = dist;  // the near plane is 4 units above the floor
      x = -4.5 + rx.u[i] * 9.0;
      z = -4.5 + rx.v[i] * 9.0;
    }
    if (std::abs(depth_r - 4.0) > 0.02) continue;  // not the floor
    const double vv = vis[i];
    if (std::abs(z) < 0.6 && x > 1.0 - expected && x < 1.0 + expected && vv >= 0.1 && vv <= 0.9) {
      n += 1;
      sx += x;
      sy += vv;
      sxx += x * x;
      sxy += x * vv;
    }
    // Umbra: under the occluder, beyond the penumbra's inner half (the camera sees the floor
    // under the occluder only near the edge x = 1).
    if (x > -1.0 && x < 1.0 - 0.5 * expected - 0.05 && std::abs(z) < 0.5) {
      ++umbra;
      umbra_bad += vv > 0.05;
    }
  }
  ASSERT_GT(n, 30) << "too few penumbra receivers; umbra receivers " << umbra;
  ASSERT_GT(umbra, 50u) << "ramp receivers " << n;
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double measured = 1.0 / slope;
  std::printf(
      "  %s %s%s, light %g x %g: penumbra %.4f, formula %.4f (%+.1f%%), %d ramp receivers, umbra > 0.05: "
      "%zu of %zu\n",
      c.perspective ? "perspective" : "ortho", soft_method_name(c.method),
      c.method == SoftMethod::Cssm ? (c.lookup == Lookup::Sat ? " sat" : " mips") : "", L, light_height(o.light),
      measured, expected, 100 * (measured / expected - 1), int(n), umbra_bad, umbra);
  EXPECT_NEAR(measured, expected, 0.10 * expected);
  EXPECT_LE(umbra_bad, umbra / 100);
}

INSTANTIATE_TEST_SUITE_P(
    Methods, SoftParallelPlanes,
    ::testing::Values(
        PlanesCase{false, SoftMethod::Pcss, Lookup::Sat}, PlanesCase{false, SoftMethod::Cssm, Lookup::Sat},
        PlanesCase{false, SoftMethod::Cssm, Lookup::Mips}, PlanesCase{false, SoftMethod::Ssmm, Lookup::Sat},
        PlanesCase{false, SoftMethod::SsmmImproved, Lookup::Sat}, PlanesCase{true, SoftMethod::Pcss, Lookup::Sat},
        PlanesCase{true, SoftMethod::Cssm, Lookup::Sat}, PlanesCase{true, SoftMethod::Cssm, Lookup::Mips},
        PlanesCase{true, SoftMethod::Ssmm, Lookup::Sat}, PlanesCase{true, SoftMethod::SsmmImproved, Lookup::Sat},
        PlanesCase{false, SoftMethod::Pcss, Lookup::Sat, 1.5}, PlanesCase{false, SoftMethod::Cssm, Lookup::Sat, 1.5},
        PlanesCase{false, SoftMethod::Ssmm, Lookup::Sat, 1.5}),
    [](const auto& info) {
      std::string s = std::string(info.param.perspective ? "persp_" : "ortho_") + soft_method_name(info.param.method);
      std::replace(s.begin(), s.end(), '-', '_');
      if (info.param.method == SoftMethod::Cssm) s += info.param.lookup == Lookup::Sat ? "_sat" : "_mips";
      if (info.param.height >= 0) s += "_rect";
      return s;
    });

// Perspective cssm against the ray-traced reference: the built-in spheres scene under a
// perspective light (as `shadowfilter scene spheres --light perspective`, 512 map, 640 x 480
// receivers, 16 samples), RMSE and p99 |err| against reference_soft over the non-background
// receivers, relative to pcss on the same input. At 640 x 480 / 64 samples (docs/soft.md) pcss
// 0.083 / 0.47, cssm M = 4 mips 0.090 / 0.41, M = 16 mips 0.076 / 0.35, M = 4 sat 0.092 / 0.44; the
// old defaults (offset 0.5 / M, scale 1, no contact path) gave 0.23 / 1.0 at M = 4.
TEST(SoftCssm, PerspectiveSceneAgainstRayTracedReference) {
  SceneRequest req;
  req.scene = "spheres";
  req.light = "perspective";
  req.map_size = 512;
  req.receivers = "640x480";
  req.samples = 16;
  req.progress = false;
  req.out_dir = temp_dir("soft_persp_scene");  // make_setup writes nothing
  const SceneSetup setup = make_setup(req);
  const SceneRenderer renderer(setup);
  const HostImage depth = renderer.shadow_map();
  const CameraImages cam = renderer.camera_view(true);
  const Receivers rx = receivers_of(cam.receivers);
  SoftLight light;
  light.perspective = true;
  light.size = setup.light_size;
  light.near_plane = setup.light.near_plane;
  light.far_plane = setup.light.far_plane;
  light.fov_degrees = setup.light.fov_degrees;
  struct Err {
    double rmse, p99;
  };
  auto measure = [&](SoftMethod m, int order, Lookup lookup, bool plane = true) {
    SoftOptions o;
    o.method = m;
    o.receiver_plane.enabled = plane;
    o.cssm.order = order;
    o.cssm.lookup = lookup;
    o.light = light;
    const std::vector<float> vis = run_device(o, depth, rx);
    std::vector<double> err;
    double se = 0;
    for (size_t i = 0; i < vis.size(); ++i) {
      if (!std::isfinite(rx.d[i])) continue;
      const double e = vis[i] - cam.reference_soft.data[i];
      err.push_back(std::abs(e));
      se += e * e;
    }
    std::sort(err.begin(), err.end());
    EXPECT_GT(err.size(), 5000u);
    const Err r{std::sqrt(se / err.size()), err[size_t(0.99 * (err.size() - 1))]};
    std::printf("  perspective spheres, %s M=%d %s%s: RMSE %.4f, p99 %.3f\n", soft_method_name(m), order,
                lookup == Lookup::Sat ? "sat" : "mips", plane ? "" : " (receiver plane off)", r.rmse, r.p99);
    return r;
  };
  // cssm against the seed's pcss (the plain test against d); pcss with the receiver plane must
  // beat it on this scene's tilted and curved receivers.
  const Err pcss = measure(SoftMethod::Pcss, 4, Lookup::Sat, false);
  const Err pcss_plane = measure(SoftMethod::Pcss, 4, Lookup::Sat);
  EXPECT_LT(pcss_plane.rmse, pcss.rmse);
  const Err m4 = measure(SoftMethod::Cssm, 4, Lookup::Mips), m16 = measure(SoftMethod::Cssm, 16, Lookup::Mips);
  const Err s4 = measure(SoftMethod::Cssm, 4, Lookup::Sat);
  EXPECT_LT(m4.rmse, 1.3 * pcss.rmse);
  EXPECT_LT(m16.rmse, 1.2 * pcss.rmse);
  EXPECT_LT(std::abs(m4.rmse - s4.rmse), 0.02) << "mips and SAT must agree on this scene";
  for (const Err& e : {m4, m16, s4}) EXPECT_LT(e.p99, 0.6);
}

// Several lights: v = sum w_i v_i / sum w_i of the single-light results (weights 1 and 3, the
// second light twice as wide). Float sums of two terms: within 1e-6.
TEST(SoftLights, WeightedCombination) {
  const HostImage depth = blocky_map(64);
  Receivers rx;
  rx.width = 400;
  rx.height = 1;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int i = 0; i < rx.width; ++i) {
    rx.u.push_back(uni(rng));
    rx.v.push_back(uni(rng));
    rx.d.push_back(0.8f);
  }
  SoftOptions o = ortho_options(SoftMethod::Ssmm, 0.1, 1.0);
  SoftLight a = o.light, b = o.light;
  a.weight = 1.0;
  b.weight = 3.0;
  b.size = 0.2;
  const SoftResult both = soft_filter_lights(runtime_ptr(), o, {{a, depth, rx}, {b, depth, rx}});
  o.light = a;
  const SoftResult ra = soft_filter(runtime_ptr(), o, depth, rx);
  o.light = b;
  const SoftResult rb = soft_filter(runtime_ptr(), o, depth, rx);
  size_t differ = 0;
  for (int i = 0; i < rx.width; ++i) {
    EXPECT_NEAR(both.visibility.data[i], (ra.visibility.data[i] + 3.0 * rb.visibility.data[i]) / 4.0, 1e-6);
    differ += std::abs(ra.visibility.data[i] - rb.visibility.data[i]) > 0.01;
  }
  EXPECT_GT(differ, 20u) << "the two lights must give different shadows";
}

// A technique is selected by value; its name is looked up once, at the boundary, and an unknown
// name is refused with the known ones.
TEST(SoftOptionsApi, MethodNamesRoundTripAndUnknownIsRefused) {
  for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved})
    EXPECT_EQ(find_soft_method(soft_method_name(m)), m);
  try {
    find_soft_method("cssm2");
    FAIL() << "an unknown soft method must throw";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown soft method 'cssm2' (known: pcss, cssm, ssmm, ssmm-improved)");
  }
  // The one receivers type: SoftFilter reads its map part as points; grid receivers are refused.
  SoftFilter filter(runtime_ptr(), SoftOptions{}, 8, 8);
  DeviceReceivers grid;
  grid.grid = true;
  grid.count = 64;
  grid.d = to_device(std::vector<float>(64, 0.5f));
  EXPECT_THROW(filter.reconstruct(grid, grid.d), InputError);
  SoftOptions o;
  o.method = SoftMethod::Cssm;
  o.cssm.order = 33;
  EXPECT_THROW(validate(o), InputError);
  o.cssm.order = 4;
  o.ssmm.n = 0;
  EXPECT_THROW(validate(o), InputError);
  // cssm's narrow bases: f16 and unorm16 with mips; the SAT (float-float whatever its input) and
  // unorm8 (docs/soft.md: 0.03-0.05 RMS from float32's visibility) are refused.
  o.ssmm.n = 4;
  o.cssm.lookup = Lookup::Mips;
  for (Storage st : {Storage::F16, Storage::Unorm16}) {
    o.cssm.storage = st;
    EXPECT_NO_THROW(validate(o)) << storage_name(st);
  }
  o.cssm.storage = Storage::Unorm8;
  EXPECT_THROW(validate(o), InputError);
  o.cssm.storage = Storage::F16;
  o.cssm.lookup = Lookup::Sat;
  try {
    validate(o);
    FAIL() << "f16 with the SAT must throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs SoftOptions::cssm.lookup mips"), std::string::npos) << e.what();
  }
}

// Degenerate input: every texel at the receiver depth (1 - s_f = 0 for cssm up to ringing), a
// light of size 0, receivers at d = 0 and 1: finite visibility everywhere, lit where nothing blocks.
TEST(SoftGuards, NoNaNOnDegenerateInput) {
  HostImage depth(32, 32, 1, 0.5f);
  Receivers rx;
  rx.width = 4;
  rx.height = 1;
  rx.u = {0.5f, 0.3f, 0.7f, 0.1f};
  rx.v = {0.5f, 0.3f, 0.7f, 0.9f};
  rx.d = {0.5f, 0.0f, 1.0f, 0.5f};
  for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved})
    for (double L : {0.0, 0.3}) {
      SoftOptions o = ortho_options(m, L, 1.0);
      const std::vector<float> v = run_device(o, depth, rx);
      for (int i = 0; i < 4; ++i) ASSERT_TRUE(std::isfinite(v[i])) << soft_method_name(m) << " L=" << L;
      EXPECT_EQ(v[0], 1.0f) << soft_method_name(m) << ": a receiver on the only surface is lit";
      EXPECT_EQ(v[1], 1.0f) << soft_method_name(m);
      EXPECT_LT(v[2], 0.05f) << soft_method_name(m) << ": d = 1 under z = 0.5 is in shadow";
    }
}

}  // namespace
}  // namespace sf::test

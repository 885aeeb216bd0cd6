// Receiver-plane depth (kernels/receiver_plane.clh, docs/receiver_plane.md): tilted planes with
// no occluder stay lit under sm and pcf with their defaults, s_ref of the receivers' planes is
// exactly 1, and the kernels' planes match the double reference's.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "lookups.hpp"
#include "receiver_plane.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/normal_offset.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/soft.hpp"

using namespace sf;
using namespace sf::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A plane tilted by `degrees` towards direction `phi` (radians) under an orthographic light: a
// W x W map of a square as deep as `depth_per_side` map widths, depth 0.5 at the centre.
struct TiltedPlane {
  int W = 64;
  double gx = 0, gy = 0;  // depth per texel
  TiltedPlane(int w, double degrees, double phi, double depth_per_side) : W(w) {
    const double g = std::tan(degrees * kPi / 180.0) / (W * depth_per_side);
    gx = g * std::cos(phi);
    gy = g * std::sin(phi);
  }
  double at(double x, double y) const { return 0.5 + gx * (x - 0.5 * (W - 1)) + gy * (y - 0.5 * (W - 1)); }
  HostImage map() const {
    HostImage m(W, W, 1);
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) m.at(x, y) = float(at(x, y));
    return m;
  }
  // A camera's view of the plane: an rw x rh receiver image whose pixels step by `step` texels
  // along a grid rotated by `alpha`, each receiver on the plane (depth at its own (u, v)).
  Receivers receivers(int rw, int rh, double step, double alpha) const {
    Receivers rx;
    rx.width = rw;
    rx.height = rh;
    for (int j = 0; j < rh; ++j)
      for (int i = 0; i < rw; ++i) {
        const double a = (i - 0.5 * rw) * step, b = (j - 0.5 * rh) * step;
        const double x = 0.5 * (W - 1) + 0.37 + a * std::cos(alpha) - b * std::sin(alpha);
        const double y = 0.5 * (W - 1) - 0.21 + a * std::sin(alpha) + b * std::cos(alpha);
        const float u = float((x + 0.5) / W), v = float((y + 0.5) / W);
        rx.u.push_back(u);
        rx.v.push_back(v);
        rx.d.push_back(float(at(double(u) * W - 0.5, double(v) * W - 0.5)));
      }
    return rx;
  }
};

// sm and pcf (prefilter radius R) with their defaults keep every receiver lit to 1/255.
void expect_sm_and_pcf_lit(const HostImage& map, const Receivers& rx, int radius, const std::string& what) {
  for (const std::string method : {"sm", "pcf"}) {
    FilterOptions o;
    o.method = method;
    o.blur.radius = radius;
    const auto got = filter(runtime_ptr(), o, map, rx).visibility.data;
    for (size_t i = 0; i < rx.count(); ++i)
      ASSERT_GE(got[i], 1.0f - 1.0f / 255.0f) << method << " " << what << " receiver " << i;
  }
}

}  // namespace

// Slopes up to 80 degrees, several directions and camera rotations: no receiver self-shadows.
TEST(ReceiverPlane, TiltedPlanesStayLit) {
  for (const double degrees : {0.0, 30.0, 60.0, 80.0})
    for (const double phi : {0.0, 0.7, 2.5})
      for (const double alpha : {0.0, 0.4}) {
        const TiltedPlane plane(64, degrees, phi, 8.0);
        const HostImage map = plane.map();
        const Receivers rx = plane.receivers(24, 20, 0.73, alpha);
        const std::string what =
            std::to_string(int(degrees)) + " deg phi " + std::to_string(phi) + " alpha " + std::to_string(alpha);
        expect_sm_and_pcf_lit(map, rx, 2, what);
        // s_ref of the receivers' planes with the default bias: every test lit (the weights sum
        // to 1 within double rounding).
        FilterOptions o;
        o.method = "pcf";
        o.blur.radius = 2;
        for (size_t i = 0; i < rx.count(); ++i) {
          const ref::Plane p = ref::receiver_plane(map, rx, i, o.receiver_plane);
          ASSERT_NEAR(ref::s_ref(map, o.blur, Lookup::Bilinear, rx.u[i], rx.v[i], p, 1.0, depth_bias(o)), 1.0, 1e-12)
              << what << " receiver " << i;
        }
      }
}

// The same planes in the grid mode (--receiver-depth: the plane itself at the texel centres).
TEST(ReceiverPlane, TiltedGridStaysLit) {
  for (const double degrees : {30.0, 80.0}) {
    const TiltedPlane plane(48, degrees, 0.9, 8.0);
    const HostImage map = plane.map();
    Receivers rx;
    rx.grid = true;
    rx.width = rx.height = map.width;
    rx.d = map.data;
    expect_sm_and_pcf_lit(map, rx, 3, "grid " + std::to_string(int(degrees)) + " deg");
  }
}

// Without the plane the same receivers self-shadow (the test above can fail), and the kernels'
// planes equal the reference's: pcf against ref::filter on tilted planes and a random map.
TEST(ReceiverPlane, FlatTestShadowsTiltedPlanesAndKernelsMatchReference) {
  const TiltedPlane plane(64, 60.0, 0.7, 8.0);
  const HostImage map = plane.map();
  const Receivers rx = plane.receivers(24, 20, 0.73, 0.4);
  FilterOptions o;
  o.method = "pcf";
  o.blur.radius = 2;
  o.receiver_plane.enabled = false;
  const auto flat = filter(runtime_ptr(), o, map, rx).visibility.data;
  size_t dark = 0;
  for (float v : flat) dark += v < 0.9f;
  EXPECT_GT(dark, rx.count() / 4) << "a flat test on a 60-degree plane";

  o.receiver_plane.enabled = true;
  const HostImage random = random_depth(40, 36, 5, 0.2f, 0.8f);
  for (const HostImage* m : {&map, &random}) {
    const auto got = filter(runtime_ptr(), o, *m, rx).visibility.data;
    const auto want = ref::filter(o, *m, rx);
    size_t off = 0;
    for (size_t i = 0; i < rx.count(); ++i) off += std::abs(got[i] - want[i]) > 1e-5;
    // Float and double may round an exact tie apart: a handful, never more.
    EXPECT_LE(off, rx.count() / 100) << (m == &map ? "plane" : "random");
  }
}

// Every method with its defaults (prefilter radius 2 where it applies), the soft methods with a
// light a tenth of the map wide: planes up to 80 degrees stay lit to 1/255 (the first check of the
// test; the prefiltered methods' own regularisation keeps a plane's moments lit, the depth tests
// their plane and slope-scaled bias).
TEST(ReceiverPlane, EveryMethodKeepsTiltedPlanesLit) {
  for (const double degrees : {0.0, 45.0, 80.0})
    for (const double phi : {0.0, 2.5}) {
      const TiltedPlane plane(64, degrees, phi, 8.0);
      const HostImage map = plane.map();
      const Receivers rx = plane.receivers(24, 20, 0.73, 0.4);
      const std::string what = std::to_string(int(degrees)) + " deg phi " + std::to_string(phi);
      for (const MethodDesc& m : methods()) {
        FilterOptions o;
        o.method = m.name;
        if (m.filtered) o.blur.radius = 2;
        const auto got = filter(runtime_ptr(), o, map, rx).visibility.data;
        EXPECT_GE(*std::min_element(got.begin(), got.end()), 1.0f - 1.0f / 255.0f) << m.name << " " << what;
      }
      for (SoftMethod sm : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}) {
        SoftOptions o;
        o.method = sm;
        o.light.size = 0.1;
        o.light.extent = 1.0;
        const auto got = soft_filter(runtime_ptr(), o, map, rx).visibility.data;
        EXPECT_GE(*std::min_element(got.begin(), got.end()), 1.0f - 1.0f / 255.0f)
            << soft_method_name(sm) << " " << what;
      }
    }
}

// ---- normal offset (normal_offset.hpp) ----------------------------------------------------------

namespace {

// The plane's texel-scaled normals: the map spans one world unit across W texels and
// depth_per_side world units of depth, so a texel is w = 1 / W wide and d moves by 1 per
// depth_per_side. The unit normal towards the light (right, down, forward) is
// (gx', gy', -1) / |.|, with gx', gy' the world slopes; one texel along it is (n.x, n.y, n.z w / R).
void add_normals(const TiltedPlane& plane, double depth_per_side, Receivers& rx) {
  const double world_gx = plane.gx * plane.W * depth_per_side, world_gy = plane.gy * plane.W * depth_per_side;
  const double len = std::sqrt(world_gx * world_gx + world_gy * world_gy + 1.0);
  rx.has_normal = true;
  rx.nx.assign(rx.count(), float(world_gx / len));
  rx.ny.assign(rx.count(), float(world_gy / len));
  rx.nz.assign(rx.count(), float(-1.0 / len / (plane.W * depth_per_side)));
}

}  // namespace

// texel_scaled_normal from an orthographic light's Jacobian equals the plane's normal scaled by
// hand; offset_along_normals moves u, v, d by t (nx / W, ny / H, nz), leaves unknown normals
// alone, and refuses offsets outside [0, kMaxNormalOffset].
TEST(NormalOffset, ScalesAndMovesExactly) {
  const int W = 64;
  const double R = 8.0;  // depth_per_side: the depth range in map widths
  const double jacobian[3][3] = {{double(W), 0, 0}, {0, double(W), 0}, {0, 0, 1.0 / R}};
  const Vec3 n = normalize(Vec3{0.3, -0.4, -1.0});
  const std::array<float, 3> s = texel_scaled_normal(jacobian, n);
  EXPECT_NEAR(s[0], n.x, 1e-7);
  EXPECT_NEAR(s[1], n.y, 1e-7);
  EXPECT_NEAR(s[2], n.z / (W * R), 1e-9);

  Receivers rx;
  rx.width = 2;
  rx.height = 1;
  rx.u = {0.5f, 0.25f};
  rx.v = {0.5f, 0.75f};
  rx.d = {0.5f, 0.4f};
  rx.has_normal = true;
  rx.nx = {s[0], NAN};
  rx.ny = {s[1], 0.0f};
  rx.nz = {s[2], 0.0f};
  const Receivers moved = offset_along_normals(rx, W, 2 * W, 1.5f);
  EXPECT_FLOAT_EQ(moved.u[0], 0.5f + 1.5f * s[0] / W);
  EXPECT_FLOAT_EQ(moved.v[0], 0.5f + 1.5f * s[1] / (2 * W));
  EXPECT_FLOAT_EQ(moved.d[0], 0.5f + 1.5f * s[2]);
  EXPECT_EQ(moved.u[1], rx.u[1]);  // unknown normal: not moved
  EXPECT_EQ(moved.d[1], rx.d[1]);
  for (const float bad : {-0.5f, kMaxNormalOffset + 1.0f, float(NAN)})
    EXPECT_THROW(offset_along_normals(rx, W, W, bad), InputError) << bad;
  rx.nz.pop_back();
  EXPECT_THROW(offset_along_normals(rx, W, W, 1.0f), InputError);
}

// A plane tilted 80 degrees, tested flat (no receiver plane, no bias): the plain test shadows a
// good part of it (acne), and one and a half texels along the normal light every receiver. The
// moved receiver is k w / cos(theta) nearer the light along its axis, k / sin(theta) >= k times
// the plane's depth change per texel, and the 2x2 test reads texels less than one texel away per
// axis (|gx| + |gy| <= sqrt(2) g). filter(), soft_filter() and ref::filter with the offset equal
// the same calls on receivers moved by hand.
TEST(NormalOffset, LightsGrazingPlaneTestedFlat) {
  const double R = 8.0;
  const TiltedPlane plane(64, 80.0, 0.7, R);
  const HostImage map = plane.map();
  Receivers rx = plane.receivers(24, 20, 0.73, 0.4);
  add_normals(plane, R, rx);
  FilterOptions o;
  o.method = "sm";
  o.receiver_plane.enabled = false;
  o.depth_test.bias = 0.0f;
  o.normal_offset = 0.0f;  // sm's default is half a texel
  auto shadowed = [&](const std::vector<float>& v) {
    return size_t(std::count_if(v.begin(), v.end(), [](float x) { return !(x >= 1.0f - 1.0f / 255.0f); }));
  };
  const size_t plain = shadowed(filter(runtime_ptr(), o, map, rx).visibility.data);
  EXPECT_GT(plain, rx.count() / 4) << "the flat test must self-shadow without the offset";
  o.normal_offset = 1.5f;
  const std::vector<float> offset = filter(runtime_ptr(), o, map, rx).visibility.data;
  EXPECT_EQ(shadowed(offset), 0u);

  const Receivers moved = offset_along_normals(rx, map.width, map.height, 1.5f);
  FilterOptions by_hand = o;
  by_hand.normal_offset = 0.0f;
  EXPECT_EQ(filter(runtime_ptr(), by_hand, map, moved).visibility.data, offset);
  const std::vector<double> twin = ref::filter(o, map, rx), twin_by_hand = ref::filter(by_hand, map, moved);
  EXPECT_EQ(twin, twin_by_hand);

  SoftOptions s;
  s.method = SoftMethod::Pcss;
  s.light.size = 0.1;
  s.light.extent = 1.0;
  s.normal_offset = 1.5f;
  const std::vector<float> soft = soft_filter(runtime_ptr(), s, map, rx).visibility.data;
  s.normal_offset = 0.0f;
  EXPECT_EQ(soft_filter(runtime_ptr(), s, map, moved).visibility.data, soft);
}

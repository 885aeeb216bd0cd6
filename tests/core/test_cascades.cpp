// The layout fits of cascades.hpp (pure math, no device): practical splits, stabilisation, the
// trapezoid's 80% rule, depth ranges and validation.
#include <gtest/gtest.h>

#include <cmath>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/errors.hpp"

namespace {

using sf::CameraFrustum;
using sf::CascadeSet;
using sf::LayoutKind;
using sf::LayoutOptions;
using sf::Point3;

constexpr double kPi = 3.14159265358979323846;

// A camera 2 units over the ground looking along -z, slightly down; a 2 km ground and a tower.
CameraFrustum camera(double yaw_degrees = 0.0, Point3 position = {0, 2, 0}) {
  CameraFrustum c;
  c.position = position;
  const double yaw = yaw_degrees * kPi / 180.0, pitch = -5.0 * kPi / 180.0;
  c.forward = {-std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch)};
  // up: orthogonal to forward, in the vertical plane through it.
  c.up = {-std::sin(yaw) * -std::sin(pitch), std::cos(pitch), -std::cos(yaw) * -std::sin(pitch)};
  c.vertical_fov_degrees = 50;
  c.aspect = 16.0 / 9.0;
  c.near_depth = 1;
  c.far_depth = 800;
  return c;
}

std::vector<sf::WorldBox> world() { return {{{-1000, 0, -1000}, {1000, 0, 1000}}, {{-5, 0, -60}, {5, 40, -50}}}; }

const Point3 kLight{0.4, -1.0, 0.3};

TEST(Cascades, PracticalSplitsBlendUniformAndLogarithmic) {
  const auto uniform = sf::practical_splits(1, 1000, 4, 0.0);
  const auto logarithmic = sf::practical_splits(1, 1000, 4, 1.0);
  const auto half = sf::practical_splits(1, 1000, 4, 0.5);
  ASSERT_EQ(half.size(), 5u);
  for (int i = 0; i <= 4; ++i) {
    EXPECT_NEAR(uniform[i], 1 + 999 * i / 4.0, 1e-9);
    EXPECT_NEAR(logarithmic[i], std::pow(1000.0, i / 4.0), 1e-9);
    EXPECT_NEAR(half[i], 0.5 * (uniform[i] + logarithmic[i]), 1e-9);
  }
  EXPECT_THROW(sf::practical_splits(0, 10, 4, 0.5), sf::InputError);
  EXPECT_THROW(sf::practical_splits(1, 10, 9, 0.5), sf::InputError);
  EXPECT_THROW(sf::practical_splits(1, 10, 4, 1.5), sf::InputError);
}

// Every layer covers its whole slice: the slice's 8 corners project inside [0, 1]^2 with w > 0.
TEST(Cascades, EveryLayoutCoversItsSlices) {
  for (LayoutKind kind : {LayoutKind::Single, LayoutKind::Pssm, LayoutKind::Tsm, LayoutKind::PssmTsm}) {
    for (bool stabilize : {true, false}) {
      LayoutOptions o;
      o.kind = kind;
      o.cascades = 3;
      o.map_size = 512;
      o.stabilize = stabilize;
      const CameraFrustum cam = camera(20);
      const CascadeSet set = sf::fit_layout(o, cam, kLight, world());
      for (const auto& layer : set.layers)
        for (const Point3& p : cam.slice_corners(layer.split_near, layer.split_far)) {
          const auto q = layer.transform.apply(p);
          SCOPED_TRACE(std::string(sf::layout_name(kind)) + (stabilize ? " stable" : " tight"));
          EXPECT_GT(q.w, 0.0);
          EXPECT_GE(q.u, -1e-9);
          EXPECT_LE(q.u, 1 + 1e-9);
          EXPECT_GE(q.v, -1e-9);
          EXPECT_LE(q.v, 1 + 1e-9);
        }
    }
  }
}

// Stabilised: turning the camera keeps each layer's texel size and puts its texel grid on the same
// world lines (the map's origin moves by whole texels).
TEST(Cascades, StabilisedLayersKeepTheirTexelGridAsTheCameraTurns) {
  LayoutOptions o;
  o.kind = LayoutKind::Pssm;
  o.cascades = 4;
  o.map_size = 1024;
  const CascadeSet a = sf::fit_layout(o, camera(0), kLight, world());
  const CascadeSet b = sf::fit_layout(o, camera(37, {3.3, 2, -7.1}), kLight, world());
  for (size_t k = 0; k < a.layers.size(); ++k) {
    const Point3 p{0.7, 0.0, -9.3};  // any world point: its texel coordinate differs by whole texels
    const auto qa = a.layers[k].transform.apply(p), qb = b.layers[k].transform.apply(p);
    const double du = (qa.u - qb.u) * o.map_size, dv = (qa.v - qb.v) * o.map_size;
    EXPECT_NEAR(du, std::round(du), 1e-6) << "layer " << k;
    EXPECT_NEAR(dv, std::round(dv), 1e-6) << "layer " << k;
    EXPECT_NEAR(sf::layer_texel_size(a, k, p), sf::layer_texel_size(b, k, p), 1e-9);
  }
  // Without stabilisation the grid moves by fractions of a texel.
  o.stabilize = false;
  const CascadeSet c = sf::fit_layout(o, camera(0), kLight, world());
  const CascadeSet d = sf::fit_layout(o, camera(37, {3.3, 2, -7.1}), kLight, world());
  const auto qc = c.layers[0].transform.apply({0.7, 0, -9.3}), qd = d.layers[0].transform.apply({0.7, 0, -9.3});
  const double du = (qc.u - qd.u) * o.map_size;
  EXPECT_GT(std::abs(du - std::round(du)), 1e-3);
}

// Cascades put more texels near the camera: cascade 0's texel is smaller than the single map's
// by about the ratio of their slices' sizes; a warped map's texel grows with the view depth.
TEST(Cascades, NearTexelsShrinkWithCascadesAndWarps) {
  LayoutOptions o;
  o.map_size = 1024;
  o.kind = LayoutKind::Single;
  const CascadeSet single = sf::fit_layout(o, camera(), kLight, world());
  o.kind = LayoutKind::Pssm;
  const CascadeSet pssm = sf::fit_layout(o, camera(), kLight, world());
  o.kind = LayoutKind::Tsm;
  const CascadeSet tsm = sf::fit_layout(o, camera(), kLight, world());
  const Point3 near_point{0, 0, -10}, far_point{0, 0, -500};
  EXPECT_LT(sf::layer_texel_size(pssm, 0, near_point), 0.2 * sf::layer_texel_size(single, 0, near_point));
  EXPECT_LT(sf::layer_texel_size(tsm, 0, near_point), 0.2 * sf::layer_texel_size(single, 0, near_point));
  EXPECT_GT(sf::layer_texel_size(tsm, 0, far_point), 5 * sf::layer_texel_size(tsm, 0, near_point));
}

// The 80% rule: the focus point (near (far/near)^tsm_focus on the camera's axis) lands on the 80%
// line of the trapezoid's map.
TEST(Cascades, TrapezoidMapsTheFocusPointToTheEightyPercentLine) {
  LayoutOptions o;
  o.kind = LayoutKind::Tsm;
  o.map_size = 1024;
  CameraFrustum cam = camera();
  // Level camera: its near face's centre is the trapezoid's top; the focus point is on the axis.
  cam.forward = {0, 0, -1};
  cam.up = {0, 1, 0};
  const CascadeSet set = sf::fit_layout(o, cam, {0.0, -1.0, 0.6}, world());
  const double focus = cam.near_depth * std::pow(cam.far_depth / cam.near_depth, o.tsm_focus);
  const Point3 p{cam.position[0], cam.position[1], cam.position[2] - focus};
  const auto top = set.layers[0].transform.apply({cam.position[0], cam.position[1], cam.position[2] - cam.near_depth});
  const auto q = set.layers[0].transform.apply(p);
  // v runs from the trapezoid's top (0) to its base (1); the top line passes near the near face.
  EXPECT_NEAR(q.v, 0.8, 0.05);
  EXPECT_LT(top.v, 0.05);
}

TEST(Cascades, LayerDepthRangeEndsAtTheSlicesDeepestPoint) {
  LayoutOptions o;
  o.kind = LayoutKind::Pssm;
  o.cascades = 4;
  o.map_size = 256;
  o.stabilize = false;
  const CameraFrustum cam = camera();
  const CascadeSet set = sf::fit_layout(o, cam, kLight, world());
  int checked = 0;
  // Receivers: the ground points seen through a grid of pixels lie inside [0, 1] in the layer
  // their view depth picks (the slice's corners themselves lie in the air or under the ground).
  const Point3 right{cam.forward[1] * cam.up[2] - cam.forward[2] * cam.up[1],
                     cam.forward[2] * cam.up[0] - cam.forward[0] * cam.up[2],
                     cam.forward[0] * cam.up[1] - cam.forward[1] * cam.up[0]};
  const double tan_half = std::tan(0.5 * cam.vertical_fov_degrees * kPi / 180.0);
  for (int iy = 0; iy <= 16; ++iy)
    for (int ix = 0; ix <= 16; ++ix) {
      const double sx = (ix / 8.0 - 1.0) * tan_half * cam.aspect, sy = (iy / 8.0 - 1.0) * tan_half;
      Point3 dir;
      for (int i = 0; i < 3; ++i) dir[i] = cam.forward[i] + sx * right[i] + sy * cam.up[i];
      if (!(dir[1] < 0.0)) continue;
      const double depth = -cam.position[1] / dir[1];  // dir's component along forward is 1
      if (depth < cam.near_depth || depth > cam.far_depth) continue;
      Point3 q;
      for (int i = 0; i < 3; ++i) q[i] = cam.position[i] + depth * dir[i];
      size_t k = 0;
      while (k + 1 < set.layers.size() && depth >= set.layers[k].split_far) ++k;
      const auto m = set.layers[k].transform.apply(q);
      ++checked;
      EXPECT_GE(m.d, 0.0);
      EXPECT_LE(m.d, 1.0);
      EXPECT_GE(m.u, 0.0);
      EXPECT_LE(m.u, 1.0);
    }
  EXPECT_GE(checked, 100);
  // The near cascade's range is far shorter than the ground's extent along the light.
  const double per_unit = std::sqrt(set.layers[0].transform.m[8] * set.layers[0].transform.m[8] +
                                    set.layers[0].transform.m[9] * set.layers[0].transform.m[9] +
                                    set.layers[0].transform.m[10] * set.layers[0].transform.m[10]);
  EXPECT_LT(1.0 / per_unit, 500.0);
}

TEST(Cascades, ValidateRefusesBrokenSets) {
  LayoutOptions o;
  o.kind = LayoutKind::Pssm;
  o.cascades = 3;
  o.map_size = 64;
  const CascadeSet good = sf::fit_layout(o, camera(), kLight, world());
  EXPECT_NO_THROW(sf::validate(good));
  const auto refused = [](CascadeSet s, const char* what) {
    try {
      sf::validate(s);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const sf::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  CascadeSet s = good;
  s.layers[1].split_near += 1.0;
  refused(s, "without gaps");
  s = good;
  std::swap(s.layers[1].split_near, s.layers[1].split_far);
  refused(s, "must increase");
  s = good;
  for (int i = 0; i < 4; ++i) s.layers[2].transform.m[4 + i] = s.layers[2].transform.m[i];  // v = u
  refused(s, "singular");
  s = good;
  s.layers[0].transform.m[5] = std::nan("");
  refused(s, "non-finite");
  s = good;
  s.blend = 1.0;
  refused(s, "blend");
  s = good;
  s.layers.clear();
  refused(s, "at least one layer");
  LayoutOptions bad = o;
  bad.tsm_focus = 2;
  EXPECT_THROW(sf::fit_layout(bad, camera(), kLight, world()), sf::InputError);
  EXPECT_THROW(sf::fit_layout(o, camera(), {0, 0, 0}, world()), sf::InputError);
  EXPECT_THROW(sf::parse_layout("lispsm"), sf::InputError);
}

}  // namespace

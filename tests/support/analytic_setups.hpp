#pragma once
// The cameras and lights the input tests render the analytic scene with (analytic_scene.hpp),
// and the comparison of a visibility image with the ray-cast truth away from shadow edges.
#include <cmath>
#include <sstream>
#include <string>

#include "analytic_scene.hpp"

namespace sf::test::analytic {

constexpr int kMapSize = 128;
constexpr int kCameraWidth = 160, kCameraHeight = 120;

inline View camera_view(ClipSpace clip, Depth depth) {
  View c = look_at({3.4, 3.6, 4.6}, {-0.2, 0.3, -0.9}, {0, 1, 0}, Kind::Perspective, clip, depth, kCameraWidth,
                   kCameraHeight);
  c.tan_half_y = std::tan(0.5 * 52.0 * M_PI / 180.0);
  c.tan_half_x = c.tan_half_y * kCameraWidth / kCameraHeight;
  c.near_plane = 0.5;
  c.far_plane = 30.0;
  return c;
}

// The sun: an orthographic light from above and to the side, covering the middle of the floor.
inline View ortho_light(ClipSpace clip, Depth depth = Depth::Conventional) {
  const V3 dir = unit({0.8, -1.0, -0.25});
  View l = look_at(V3{0.2, 0.3, -0.3} - 12.0 * dir, {0.2, 0.3, -0.3}, {0, 0, -1}, Kind::Orthographic, clip, depth,
                   kMapSize, kMapSize);
  l.half_w = l.half_h = 3.6;
  l.near_plane = 4.0;
  l.far_plane = 22.0;
  return l;
}

// A spot light above the scene.
inline View spot_light(ClipSpace clip, Depth depth) {
  View l = look_at({-3.6, 6.0, 0.8}, {0.3, 0.3, -0.6}, {0, 0, -1}, Kind::Perspective, clip, depth, kMapSize, kMapSize);
  l.tan_half_x = l.tan_half_y = std::tan(0.5 * 70.0 * M_PI / 180.0);
  l.near_plane = 2.0;
  l.far_plane = 16.0;
  return l;
}

// Whether a camera pixel's truth is the same within `radius` texels of its point in the light's
// map: the light's rays through the shifted texel positions meet the pixel's tangent plane, and
// each such point is lit or not by the same test. Pixels where it changes lie on a shadow edge
// (the map, a texel grid, cannot place the edge closer than that).
inline bool away_from_shadow_edges(const Scene& s, const View& light, V3 p, V3 n, bool truth, double radius) {
  if (std::fabs(dot(n, light.to_light(p))) < 0.1) return false;  // the terminator: a shadow edge of its own
  const double distance = light.axis_distance(p);
  const double texel = light.kind == Kind::Orthographic ? 2.0 * light.half_w / light.width
                                                        : 2.0 * distance * light.tan_half_x / light.width;
  for (int k = 0; k < 8; ++k) {
    const double angle = k * M_PI / 4.0;
    const V3 shifted =
        p + (radius * texel * std::cos(angle)) * light.right + (radius * texel * std::sin(angle)) * light.up;
    // The light's ray through `shifted`, on to the tangent plane at p.
    const V3 origin = light.kind == Kind::Orthographic ? shifted - 30.0 * light.forward : light.eye;
    const V3 dir = light.kind == Kind::Orthographic ? light.forward : unit(shifted - light.eye);
    const double den = dot(dir, n);
    if (std::fabs(den) < 1e-9) return false;
    const V3 q = origin + (dot(p - origin, n) / den) * dir;
    if (lit(s, light, q, n) != truth) return false;
  }
  return true;
}

// The JSON of a camera or light file (docs/inputs.md) holding `vp`'s matrices at full precision,
// with `extra` keys (", \"clip\": \"d3d\"") appended.
inline std::string view_json(const ViewProjection& vp, const std::string& extra = "") {
  auto list = [](const std::array<double, 16>& m) {
    std::ostringstream s;
    s.precision(17);
    s << "[";
    for (int i = 0; i < 16; ++i) s << (i ? ", " : "") << m[size_t(i)];
    s << "]";
    return s.str();
  };
  return "{\"view\": " + list(vp.view) + ", \"projection\": " + list(vp.projection) + extra + "}";
}

// The file of a View: its matrices, clip space, reversed-Z and the far depth of an infinite plane.
inline std::string view_file(const View& v) {
  std::string extra = std::string(", \"clip\": \"") + clip_space_name(v.clip) + "\"";
  if (v.depth != Depth::Conventional) extra += ", \"reversed_z\": true";
  if (v.depth == Depth::ReversedInfinite && v.kind == Kind::Perspective) {
    std::ostringstream far;
    far << v.far_plane;
    extra += ", \"far\": " + far.str();
  }
  ViewProjection vp;
  vp.view = v.view_matrix();
  vp.projection = v.projection_matrix();
  return view_json(vp, extra);
}

struct Mismatches {
  size_t compared = 0, mismatched = 0, skipped = 0;
  double fraction() const { return compared ? double(mismatched) / double(compared) : 1.0; }
};

// Visibility (> 0.5 = lit) against the ray-cast truth over the camera's surface pixels away from
// shadow edges (1.5 texels).
inline Mismatches compare_with_truth(const Scene& s, const View& light, const CameraTruth& cam,
                                     const std::vector<float>& visibility) {
  Mismatches m;
  for (size_t i = 0; i < cam.surface.size(); ++i) {
    if (cam.surface[i] < 0) continue;
    const bool truth = lit(s, light, cam.point[i], cam.normal[i]);
    if (!away_from_shadow_edges(s, light, cam.point[i], cam.normal[i], truth, 1.5)) {
      ++m.skipped;
      continue;
    }
    ++m.compared;
    if ((visibility[i] > 0.5f) != truth) ++m.mismatched;
  }
  return m;
}

}  // namespace sf::test::analytic

#pragma once
// Normal offset (docs/receiver_plane.md "Normal offset"): a receiver's lookup moves along its
// surface normal by a number of shadow-map texels before any method reads the map. A receiver on
// a surface the light grazes then reads texels of its own surface slightly above it, not the
// neighbouring texels of that surface that lie a texel's slope nearer the light (acne), and the
// constant bias that hid that acne, which also lets nearby occluders through (leaks), can shrink.
//
// The receivers carry the normal as Receivers::nx ny nz, scaled to one texel: the change of
// (u W, v H, d) (level-0 texels, texels, normalized depth) when the receiver moves one texel's
// world width along its unit normal (oriented towards the viewer). texel_scaled_normal computes
// it from the Jacobian of the map coordinates, which is what `scene` and `receivers` write.
#include <array>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/vec3.hpp"

namespace sf {

// Largest offset accepted, in texels: a lookup moved further has left the receiver's surface.
constexpr float kMaxNormalOffset = 8.0f;

// The texel-scaled normal of a receiver whose unit normal is `normal` (world units) where the
// map coordinates (u W, v H, d) change with the world position by `jacobian` (rows: u W, v H,
// d; columns: world x, y, z). One texel's world width is 1 / sqrt(|grad uW| |grad vH|), the
// geometric mean of the texel's sides at the point. NaN components where the Jacobian has no
// texel width (a degenerate projection).
std::array<float, 3> texel_scaled_normal(const double jacobian[3][3], const Vec3& normal);

// The same at a world point from its map coordinates: `map(p)` gives (u W, v H, d) of a world
// point p as std::array<double, 3>; the Jacobian at `point` by central differences over `step`
// world units (far below a texel: exact where the projection is affine, an orthographic light).
template <class Map>
std::array<float, 3> texel_scaled_normal(const Map& map, const Vec3& point, const Vec3& normal, double step) {
  double jacobian[3][3];
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 delta{0.0, 0.0, 0.0};
    delta[axis] = step;
    const std::array<double, 3> a = map(point - delta), b = map(point + delta);
    for (int r = 0; r < 3; ++r) jacobian[r][axis] = (b[size_t(r)] - a[size_t(r)]) / (2.0 * step);
  }
  return texel_scaled_normal(jacobian, normal);
}

// The receivers with each lookup moved `texels` along its normal: u += t nx / W, v += t ny / H,
// d += t nz, for every receiver with finite nx ny nz (others, and receivers without normals,
// unchanged). InputError for `texels` outside [0, kMaxNormalOffset] or not finite, or normals
// whose arrays do not match the receivers.
Receivers offset_along_normals(const Receivers& receivers, int map_width, int map_height, float texels);

}  // namespace sf

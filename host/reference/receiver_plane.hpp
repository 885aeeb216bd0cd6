#pragma once
// Receiver-plane depth in double precision (kernels/receiver_plane.clh; docs/receiver_plane.md):
// the plane each receiver is tested against, by the same rules as the kernels.
#include <cmath>
#include <cstddef>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"

namespace sf::ref {

// Depth d at texel-space (x, y) = (u W - 1/2, v H - 1/2), gradient (gx, gy) per level-0 texel.
struct Plane {
  double d = 0, x = 0, y = 0, gx = 0, gy = 0;
  double at(double tx, double ty) const { return d + gx * (tx - x) + gy * (ty - y); }
  // The test's bias: b plus slope_bias texels of the plane's slope (sf_plane_bias).
  double bias(double b, double slope_bias) const { return b + slope_bias * (std::abs(gx) + std::abs(gy)); }
};

// The constant d at (u, v): the plain depth test (x, y rounded to float32 as the kernels do).
Plane flat_plane(int width, int height, double u, double v, double d);

// Receiver i of rx against the W x H depth map: its plane, flat when `o` is off. d is clamped to
// [0, 1] as every test clamps it; background and outside receivers get a flat plane.
Plane receiver_plane(const HostImage& depth, const Receivers& rx, size_t i, const ReceiverPlaneOptions& o);

}  // namespace sf::ref

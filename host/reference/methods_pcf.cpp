// sm / pcf reference (kernels/pcf.cl): the depth test per texel under the composite weights,
// brute force over (2R+1)^2 Gaussian taps of each of the 4 bilinear taps (deliberately the
// naive form; the kernel folds them into one (2R+2)^2 window).
#include <algorithm>
#include <cmath>

#include "receiver_plane.hpp"
#include "reference.hpp"

namespace sf::ref {

double pcf(const HostImage& depth, const BlurOptions& blur_opt, double u, double v, double d, double bias) {
  if (!std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v) || u < 0 || u > 1 || v < 0 || v > 1) return 1.0;
  return pcf(depth, blur_opt, flat_plane(depth.width, depth.height, u, v, std::clamp(d, 0.0, 1.0)), bias);
}

double pcf(const HostImage& depth, const BlurOptions& blur_opt, const Plane& plane, double bias) {
  if (!std::isfinite(plane.d)) return 1.0;
  const int R = blur_opt.radius;
  const auto w = gaussian_weights(R, blur_opt.sigma);
  // The texel coordinate rounded once to float32, like the kernels' fma (see reference.cpp).
  const double x = plane.x, y = plane.y;
  const double xf = std::floor(x), yf = std::floor(y);
  const int xs[2] = {std::clamp(int(xf), 0, depth.width - 1), std::clamp(int(xf) + 1, 0, depth.width - 1)};
  const int ys[2] = {std::clamp(int(yf), 0, depth.height - 1), std::clamp(int(yf) + 1, 0, depth.height - 1)};
  const double wx[2] = {1 - (x - xf), x - xf}, wy[2] = {1 - (y - yf), y - yf};
  double acc = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (int b = -R; b <= R; ++b)
        for (int a = -R; a <= R; ++a) {
          const int tx = std::clamp(xs[i] + a, 0, depth.width - 1);
          const int ty = std::clamp(ys[j] + b, 0, depth.height - 1);
          const double z = depth.at(tx, ty);
          acc += wx[i] * wy[j] * w[std::abs(a)] * w[std::abs(b)] * ((z - plane.at(tx, ty)) + bias >= 0 ? 1.0 : 0.0);
        }
  return std::clamp(acc, 0.0, 1.0);
}

}  // namespace sf::ref

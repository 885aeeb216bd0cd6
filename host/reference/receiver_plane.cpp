// Receiver-plane depth, the double twin of kernels/receiver_plane.clh.
#include "receiver_plane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sf::ref {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool outside(double u, double v, double d) {
  return !std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v) || u < 0 || u > 1 || v < 0 || v > 1;
}

// Whether one-sided steps a and b (per unit of distance) describe one surface.
bool steps_agree(double a, double b) { return std::abs(b - a) <= 0.5 * std::max(std::abs(a), std::abs(b)); }

// Of the one-sided differences that exist: their mean where both exist and agree, else the
// smaller in magnitude; NaN when neither does.
double step(double lo, double mid, double hi) {
  const double a = mid - lo, b = hi - mid;
  if (!std::isfinite(a)) return std::isfinite(b) ? b : kNaN;
  if (!std::isfinite(b)) return a;
  if (steps_agree(a, b)) return 0.5 * (a + b);
  return std::abs(a) <= std::abs(b) ? a : b;
}

double clamp_slope(double g, double max_slope) { return std::isfinite(g) ? std::clamp(g, -max_slope, max_slope) : 0; }

// The slope of a W x H image (values at(x, y)) at texel (x, y) clamped into it.
template <typename At>
void image_slope(int W, int H, int x, int y, At at, double& gx, double& gy) {
  x = std::clamp(x, 0, W - 1);
  y = std::clamp(y, 0, H - 1);
  const double c = at(x, y);
  gx = step(x > 0 ? at(x - 1, y) : kNaN, c, x + 1 < W ? at(x + 1, y) : kNaN);
  gy = step(y > 0 ? at(x, y - 1) : kNaN, c, y + 1 < H ? at(x, y + 1) : kNaN);
}

struct Step {
  double x = 0, y = 0, d = 0;
};

// Of the receivers at i - stride and i + stride (where they exist): the step from one to the
// other where both exist and their slopes agree, else the one with the smaller |depth step|, as
// a texel-space offset and depth step.
bool axis_step(const Receivers& rx, int W, int H, size_t i, size_t stride, bool has_lo, bool has_hi, Step& s) {
  auto neighbour = [&](size_t j, Step& e) {
    const double u = rx.u[j], v = rx.v[j], d = rx.d[j];
    if (outside(u, v, d)) return false;
    e = {(u - double(rx.u[i])) * W, (v - double(rx.v[i])) * H, d - std::clamp(double(rx.d[i]), 0.0, 1.0)};
    return true;
  };
  Step a, b;
  const bool ha = has_lo && neighbour(i - stride, a), hb = has_hi && neighbour(i + stride, b);
  if (ha && hb) {
    const double la = std::hypot(a.x, a.y), lb = std::hypot(b.x, b.y);
    if (la > 0 && lb > 0 && steps_agree(-a.d / la, b.d / lb)) {
      s = {b.x - a.x, b.y - a.y, b.d - a.d};
      return true;
    }
  }
  if (ha && (!hb || std::abs(a.d) <= std::abs(b.d))) {
    s = a;
    return true;
  }
  if (hb) s = b;
  return hb;
}

}  // namespace

Plane flat_plane(int width, int height, double u, double v, double d) {
  Plane p;
  p.d = d;
  p.x = double(float(u * width - 0.5));
  p.y = double(float(v * height - 0.5));
  return p;
}

Plane receiver_plane(const HostImage& depth, const Receivers& rx, size_t i, const ReceiverPlaneOptions& o) {
  const int W = depth.width, H = depth.height;
  auto map_at = [&](int x, int y) { return double(depth.at(x, y)); };
  if (rx.grid) {
    const int x = int(i % size_t(rx.width)), y = int(i / size_t(rx.width));
    Plane p;
    p.d = std::isfinite(rx.d[i]) ? std::clamp(double(rx.d[i]), 0.0, 1.0) : double(rx.d[i]);
    p.x = x;
    p.y = y;
    if (!o.enabled || !std::isfinite(rx.d[i])) return p;
    double gx, gy;
    image_slope(
        W, H, x, y, [&](int a, int b) { return double(rx.d[size_t(b) * W + a]); }, gx, gy);
    if (!std::isfinite(gx) || !std::isfinite(gy)) {
      double mx, my;
      image_slope(W, H, x, y, map_at, mx, my);
      if (!std::isfinite(gx)) gx = mx;
      if (!std::isfinite(gy)) gy = my;
    }
    p.gx = clamp_slope(gx, o.max_slope);
    p.gy = clamp_slope(gy, o.max_slope);
    return p;
  }
  const double u = rx.u[i], v = rx.v[i], d = rx.d[i];
  if (outside(u, v, d)) return flat_plane(W, H, u, v, d);
  Plane p = flat_plane(W, H, u, v, std::clamp(d, 0.0, 1.0));
  if (!o.enabled) return p;
  bool solved = false;
  const size_t row = size_t(rx.width), count = rx.count();
  if (row > 0) {
    const size_t col = i % row;
    Step a, b;
    if (axis_step(rx, W, H, i, 1, col > 0, col + 1 < row && i + 1 < count, a) &&
        axis_step(rx, W, H, i, row, i >= row, i + row < count, b)) {
      const double det = a.x * b.y - a.y * b.x;
      const double la = std::hypot(a.x, a.y), lb = std::hypot(b.x, b.y);
      if (std::abs(det) > 1e-3 * la * lb && la > 0 && lb > 0) {
        p.gx = (a.d * b.y - b.d * a.y) / det;
        p.gy = (a.x * b.d - b.x * a.d) / det;
        solved = std::isfinite(p.gx) && std::isfinite(p.gy);
      }
    }
  }
  if (!solved)
    image_slope(W, H, int(std::floor(float(p.x + 0.5))), int(std::floor(float(p.y + 0.5))), map_at, p.gx, p.gy);
  p.gx = clamp_slope(p.gx, o.max_slope);
  p.gy = clamp_slope(p.gy, o.max_slope);
  return p;
}

}  // namespace sf::ref

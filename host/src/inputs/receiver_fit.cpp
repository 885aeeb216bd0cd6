// receiver_fit.hpp: one pass over the receivers, each compared with the 2x2 texels a bilinear
// lookup at its (u, v) reads.
#include "shadowfilter/receiver_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sf {

ReceiverFit receiver_fit(const HostImage& depth, const Receivers& receivers, double tolerance) {
  const Receivers& rx = receivers;
  ReceiverFit fit;
  fit.receivers = rx.count();
  const double inf = std::numeric_limits<double>::infinity();
  double u_lo = inf, u_hi = -inf, v_lo = inf, v_hi = -inf, d_lo = inf, d_hi = -inf;
  const int W = depth.width, H = depth.height;
  for (size_t i = 0; i < rx.count(); ++i) {
    const double d = rx.d[i];
    double u, v;
    if (rx.grid) {
      const size_t row = i / size_t(rx.width), column = i % size_t(rx.width);  // grid texel (column, row)
      u = (double(column) + 0.5) / rx.width;
      v = (double(row) + 0.5) / rx.height;
    } else {
      u = rx.u[i];
      v = rx.v[i];
    }
    if (!std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v)) {
      ++fit.background;
      continue;
    }
    u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u);
    v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
    d_lo = std::min(d_lo, d), d_hi = std::max(d_hi, d);
    if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) || W <= 0 || H <= 0) {
      ++fit.outside;
      continue;
    }
    ++fit.inside;
    const int x0 = std::clamp(int(std::floor(u * W - 0.5)), 0, W - 1), x1 = std::min(x0 + 1, W - 1);
    const int y0 = std::clamp(int(std::floor(v * H - 0.5)), 0, H - 1), y1 = std::min(y0 + 1, H - 1);
    const float z[4] = {depth.at(x0, y0), depth.at(x1, y0), depth.at(x0, y1), depth.at(x1, y1)};
    const double z_min = *std::min_element(z, z + 4), z_max = *std::max_element(z, z + 4);
    if (d < z_min - tolerance) ++fit.in_front;
    if (d > z_max + tolerance) ++fit.behind;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool any = fit.background < fit.receivers;
  fit.u_min = any ? u_lo : nan, fit.u_max = any ? u_hi : nan;
  fit.v_min = any ? v_lo : nan, fit.v_max = any ? v_hi : nan;
  fit.d_min = any ? d_lo : nan, fit.d_max = any ? d_hi : nan;
  return fit;
}

}  // namespace sf

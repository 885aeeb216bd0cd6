#include "reference.hpp"

#include "shadowfilter/methods.hpp"
#include "shadowfilter/normal_offset.hpp"

#include "lookups.hpp"
#include "receiver_plane.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

// Filters, lookups, the pipeline and s_ref; the methods live in methods_*.cpp.
namespace sf::ref {
namespace {

int clampi(int v, int lo, int hi) { return std::min(std::max(v, lo), hi); }

bool receiver_outside(double u, double v, double d) {
  return !std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v) || u < 0 || u > 1 || v < 0 || v > 1;
}

struct BilinearTaps {
  int x[2], y[2];
  double wx[2], wy[2];
};

// The texel-space coordinate u W - 1/2 rounded once to float32, exactly as the kernels compute
// it (fma). Bilinear weights multiply basis values that can differ by exp(c) (ESM), so a weight
// off by one float ulp can move the visibility by far more than the tolerance: the reference
// must start from the same coordinate, then does everything else in double.
double texel_coordinate(double u, int n) { return double(float(u * n - 0.5)); }

BilinearTaps bilinear_taps(int width, int height, double u, double v) {
  const double x = texel_coordinate(u, width), y = texel_coordinate(v, height);
  const double xf = std::floor(x), yf = std::floor(y);
  BilinearTaps t;
  t.x[0] = clampi(int(xf), 0, width - 1);
  t.x[1] = clampi(int(xf) + 1, 0, width - 1);
  t.y[0] = clampi(int(yf), 0, height - 1);
  t.y[1] = clampi(int(yf) + 1, 0, height - 1);
  t.wx[1] = x - xf;
  t.wx[0] = 1 - t.wx[1];
  t.wy[1] = y - yf;
  t.wy[0] = 1 - t.wy[1];
  return t;
}

}  // namespace

std::vector<double> gaussian_weights(int radius, double sigma) {
  if (sigma <= 0) sigma = (2.0 * radius + 1.0) / 6.0;
  std::vector<double> w(radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += std::exp(-double(k) * k / (2 * sigma * sigma));
  for (int k = 0; k <= radius; ++k) w[k] = std::exp(-double(k) * k / (2 * sigma * sigma)) / sum;
  return w;
}

Planes blur(const Planes& in, int radius, double sigma) {
  if (radius == 0) return in;
  const auto w = gaussian_weights(radius, sigma);
  Planes rows(in.width, in.height, in.channels), out(in.width, in.height, in.channels);
  for (int c = 0; c < in.channels; ++c) {
    for (int y = 0; y < in.height; ++y)
      for (int x = 0; x < in.width; ++x) {
        double acc = 0;
        for (int k = -radius; k <= radius; ++k) acc += w[std::abs(k)] * in.at(c, clampi(x + k, 0, in.width - 1), y);
        rows.at(c, x, y) = acc;
      }
    for (int y = 0; y < in.height; ++y)
      for (int x = 0; x < in.width; ++x) {
        double acc = 0;
        for (int k = -radius; k <= radius; ++k) acc += w[std::abs(k)] * rows.at(c, x, clampi(y + k, 0, in.height - 1));
        out.at(c, x, y) = acc;
      }
  }
  return out;
}

double bilinear(const Planes& img, int channel, double u, double v) {
  const BilinearTaps t = bilinear_taps(img.width, img.height, u, v);
  double acc = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) acc += t.wx[i] * t.wy[j] * img.at(channel, t.x[i], t.y[j]);
  return acc;
}

namespace {

void receiver_at(const Receivers& rx, size_t i, double& u, double& v, double& d) {
  d = rx.d[i];
  if (rx.grid) {
    u = texel_centre(int(i % rx.width), rx.width);
    v = texel_centre(int(i / rx.width), rx.height);
  } else {
    u = rx.u[i];
    v = rx.v[i];
  }
}

}  // namespace

namespace {
// sf::filter's last step (sf::shadow_facing_away): receivers with ndl <= 0 are 0.
void shadow_facing_away(const FilterOptions& opt, const Receivers& rx, std::vector<double>& out) {
  if (!opt.facing_away_shadowed || !rx.has_ndl) return;
  for (size_t i = 0; i < out.size(); ++i)
    if (rx.ndl[i] <= 0.0f && std::isfinite(rx.d[i])) out[i] = 0.0;
}
}  // namespace

std::vector<double> filter(const FilterOptions& opt, const HostImage& depth, const Receivers& rx) {
  // sf::filter's first step: the lookups moved along the receivers' normals (the same float
  // transform, normal_offset.hpp), then everything below on the moved receivers.
  if (const float t = normal_offset(opt); t != 0.0f && rx.has_normal) {
    FilterOptions moved = opt;
    moved.normal_offset = 0.0f;
    return filter(moved, depth, offset_along_normals(rx, depth.width, depth.height, t));
  }
  std::vector<double> out(rx.count(), 1.0);
  const MethodDesc& method = *opt.method;
  if (method.raw_depth) {
    BlurOptions weights = opt.blur;
    if (!method.filtered) weights.radius = 0;
    // pcf follows the lookup's footprints (sm ignores them; grid receivers have f = 1).
    const bool footprints = method.filtered && opt.lookup.kind != Lookup::Bilinear && !rx.grid;
    for (size_t i = 0; i < rx.count(); ++i) {
      double u, v, d;
      receiver_at(rx, i, u, v, d);
      if (receiver_outside(u, v, d)) continue;
      const Plane plane = receiver_plane(depth, rx, i, opt.receiver_plane);
      const double bias = plane.bias(depth_bias(opt), opt.receiver_plane.slope_bias);
      out[i] = footprints ? s_ref(depth, weights, opt.lookup.kind, u, v, plane,
                                  probes_at(rx, i, opt.lookup.max_anisotropy), bias)
                          : pcf(depth, weights, plane, bias);
    }
    shadow_facing_away(opt, rx, out);
    return out;
  }
  // Stored, filtered (and stored again when prefiltered), looked up, reconstructed.
  const MethodRef m = method_ref(opt);
  Planes filtered = transform(opt, depth);
  quantise(filtered, opt.storage);
  if (opt.blur.radius > 0) {
    filtered = blur(filtered, opt.blur.radius, opt.blur.sigma);
    quantise(filtered, opt.storage);
  }
  std::vector<double> b(m.channels);
  const LookupRef lookup(filtered, opt.lookup.kind, opt.storage);  // lookups.cpp
  for (size_t i = 0; i < rx.count(); ++i) {
    double u, v, d;
    receiver_at(rx, i, u, v, d);
    if (receiver_outside(u, v, d)) continue;
    for (int c = 0; c < m.channels; ++c)
      b[c] = rx.grid ? bilinear(filtered, c, u, v) : lookup.value(c, u, v, probes_at(rx, i, opt.lookup.max_anisotropy));
    out[i] = m.visibility(b.data(), std::clamp(d, 0.0, 1.0));
  }
  shadow_facing_away(opt, rx, out);
  return out;
}

double s_ref(const HostImage& depth, const BlurOptions& blur_opt, double u, double v, double d) {
  if (receiver_outside(u, v, d)) return 1.0;
  d = std::clamp(d, 0.0, 1.0);
  const int R = blur_opt.radius;
  const auto w = gaussian_weights(R, blur_opt.sigma);
  const BilinearTaps t = bilinear_taps(depth.width, depth.height, u, v);
  double acc = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (int b = -R; b <= R; ++b)
        for (int a = -R; a <= R; ++a) {
          const int x = clampi(t.x[i] + a, 0, depth.width - 1);
          const int y = clampi(t.y[j] + b, 0, depth.height - 1);
          const double weight = t.wx[i] * t.wy[j] * w[std::abs(a)] * w[std::abs(b)];
          acc += weight * (depth.at(x, y) >= d ? 1.0 : 0.0);
        }
  return acc;
}

std::vector<double> s_ref(const HostImage& depth, const BlurOptions& blur_opt, const Receivers& rx) {
  std::vector<double> out(rx.count(), 1.0);
  for (size_t i = 0; i < rx.count(); ++i) {
    double u, v, d;
    receiver_at(rx, i, u, v, d);
    out[i] = s_ref(depth, blur_opt, u, v, d);
  }
  return out;
}

}  // namespace sf::ref

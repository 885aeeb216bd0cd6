// The reference's basis transform through the registry's double-precision twins, and the
// storage formats' rounding.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "reference.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::ref {

MethodRef method_ref(const FilterOptions& opt) {
  const MethodDesc& m = *opt.method;
  if (!m.scalar) throw std::invalid_argument("reference: method " + opt.method.name() + " has no basis");
  m.validate(opt);
  return m.scalar(opt);
}

Planes transform(const FilterOptions& opt, const HostImage& depth) {
  const MethodRef m = method_ref(opt);
  Planes out(depth.width, depth.height, m.channels);
  std::vector<double> b(m.channels);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      m.basis(depth.at(x, y), b.data());
      for (int c = 0; c < m.channels; ++c) out.at(c, x, y) = b[c];
    }
  return out;
}

namespace {

// Round to the nearest float16 (ties to even), as vstore_half_rte: 11 significant bits for
// normal halves (|v| >= 2^-14), a fixed quantum of 2^-24 below; overflow gives infinity.
double round_half(double v) {
  const float f = float(v);  // vstore_half_rte rounds the float the kernel holds
  const double a = std::fabs(double(f));
  if (a == 0.0 || !std::isfinite(a)) return f;
  int e;
  std::frexp(a, &e);  // a = m 2^e, m in [0.5, 1)
  const double quantum = a < std::ldexp(1.0, -14) ? std::ldexp(1.0, -24) : std::ldexp(1.0, e - 11);
  const double r = std::nearbyint(a / quantum) * quantum;
  return std::copysign(r > 65504.0 ? INFINITY : r, double(f));
}

}  // namespace

double quantise(double v, Storage s) {
  switch (s) {
    case Storage::F32:
      return double(float(v));
    case Storage::F16:
      return round_half(v);
    // The code, read back exactly as sf_load does (times the float reciprocal).
    case Storage::Unorm16:
      return float(std::nearbyint(std::clamp(double(float(v)) * 65535.0, 0.0, 65535.0))) * (1.0f / 65535.0f);
    case Storage::Unorm8:
      return float(std::nearbyint(std::clamp(double(float(v)) * 255.0, 0.0, 255.0))) * (1.0f / 255.0f);
  }
  return v;
}

void quantise(Planes& p, Storage s) {
  for (double& v : p.data) v = quantise(v, s);
}

}  // namespace sf::ref

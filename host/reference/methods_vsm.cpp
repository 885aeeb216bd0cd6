// VSM and EVSM references (kernels/methods/vsm.clh, evsm.clh).
#include <algorithm>
#include <cmath>

#include "methods_detail.hpp"

namespace sf::ref {
namespace {

double chebyshev(double mu, double m2, double t, double vmin) {
  if (t <= mu) return 1.0;
  const double var = std::max(m2 - mu * mu, vmin);
  return var / (var + (t - mu) * (t - mu));
}

double reduce_bleeding(double p, double a) { return std::clamp((p - a) / (1.0 - a), 0.0, 1.0); }

}  // namespace

MethodRef detail::vsm_ref(const std::vector<float>& p, const FilterOptions&) {
  const double vmin = p[0], lbr = p[1];
  MethodRef m;
  m.channels = 2;
  m.basis = [](double z, double* b) {
    b[0] = z;
    b[1] = z * z;
  };
  m.visibility = [vmin, lbr](const double* b, double d) {
    return reduce_bleeding(chebyshev(b[0], b[1], d, vmin), lbr);
  };
  return m;
}

MethodRef detail::evsm_ref(const std::vector<float>& p, const FilterOptions&, bool four) {
  const double pos = p[0], neg = p[1], vmin = p[2], lbr = p[3];
  MethodRef m;
  m.channels = four ? 4 : 2;
  m.basis = [=](double z, double* b) {
    const double w = 2 * z - 1;
    b[0] = std::exp(pos * w);
    b[1] = std::exp(2 * pos * w);
    if (four) {
      b[2] = -std::exp(-neg * w);
      b[3] = std::exp(-2 * neg * w);
    }
  };
  m.visibility = [=](const double* b, double d) {
    const double w = 2 * d - 1;
    auto side = [vmin](double m1, double m2, double t, double c) {
      const double s = vmin * c * std::fabs(t);
      return chebyshev(m1, m2, t, s * s);
    };
    double v = side(b[0], b[1], std::exp(pos * w), pos);
    if (four) v = std::min(v, side(b[2], b[3], -std::exp(-neg * w), neg));
    return reduce_bleeding(v, lbr);
  };
  return m;
}

}  // namespace sf::ref

// CSM reference (kernels/methods/csm.clh): the Fourier expansion with direct sin/cos in double.
#include <algorithm>
#include <cmath>

#include "methods_detail.hpp"

namespace sf::ref {

MethodRef detail::csm_ref(const std::vector<float>& p, const FilterOptions& opt) {
  const double alpha = p[0], offset = p[1], scale = p[2];
  const int M = opt.csm.order;
  const bool mapped = unorm(opt.storage);
  MethodRef m;
  m.channels = 2 * M;
  m.basis = [=](double z, double* b) {
    for (int k = 1; k <= M; ++k) {
      const double ck = (2 * k - 1) * M_PI;
      const double s = std::sin(ck * z), c = std::cos(ck * z);
      b[k - 1] = mapped ? 0.5 + 0.5 * s : s;
      b[M + k - 1] = mapped ? 0.5 + 0.5 * c : c;
    }
  };
  m.visibility = [=](const double* b, double d) {
    const double dp = d - offset;
    double f = 0.5;
    for (int k = 1; k <= M; ++k) {
      const double ck = (2 * k - 1) * M_PI;
      const double g = std::exp(-alpha * double(k) * k / (double(M) * M));
      const double bs = mapped ? 2 * b[k - 1] - 1 : b[k - 1];
      const double bc = mapped ? 2 * b[M + k - 1] - 1 : b[M + k - 1];
      f += 2 * g * (std::cos(ck * dp) * bs - std::sin(ck * dp) * bc) / ck;
    }
    return std::clamp(scale * f, 0.0, 1.0);
  };
  return m;
}

}  // namespace sf::ref

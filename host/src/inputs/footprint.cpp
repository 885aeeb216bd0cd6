// Anisotropic footprints: kernels/lookup.clh's sf_aniso_footprint in the same float operations.
#include "shadowfilter/footprint.hpp"

#include <algorithm>
#include <cmath>

namespace sf {

FootprintProbes footprint_probes(float jux, float jvx, float juy, float jvy, int max_anisotropy) {
  const bool finite = std::isfinite(jux) && std::isfinite(jvx) && std::isfinite(juy) && std::isfinite(jvy);
  const float L = kJacobianLimit;
  jux = finite ? std::clamp(jux, -L, L) : 1.0f;
  jvx = finite ? std::clamp(jvx, -L, L) : 0.0f;
  juy = finite ? std::clamp(juy, -L, L) : 0.0f;
  jvy = finite ? std::clamp(jvy, -L, L) : 1.0f;
  const float lx = std::sqrt(std::fma(jux, jux, jvx * jvx)), ly = std::sqrt(std::fma(juy, juy, jvy * jvy));
  const bool x_major = lx >= ly;
  const float mu = x_major ? jux : juy, mv = x_major ? jvx : jvy;
  const float ou = x_major ? juy : jux, ov = x_major ? jvy : jvx;
  const float major = std::max(lx, ly);
  const float across = major > 0.0f ? std::fabs(std::fma(jux, jvy, -jvx * juy)) / major : 0.0f;
  const float ratio = major / std::max(across, 1.0f);
  FootprintProbes p;
  p.n = int(std::clamp(std::ceil(ratio * 0.99f), 1.0f, float(std::max(max_anisotropy, 1))));
  const float n = float(p.n);
  p.du = mu / n;
  p.dv = mv / n;
  p.f = major / n;
  p.fx = std::fabs(p.du) + std::fabs(ou);
  p.fy = std::fabs(p.dv) + std::fabs(ov);
  return p;
}

float isotropic_footprint(float dudx, float dvdx, float dudy, float dvdy) {
  return std::max(std::hypot(dudx, dvdx), std::hypot(dudy, dvdy));
}

void isotropic_where_unknown(Receivers& rx) {
  if (!rx.has_jacobian) return;
  for (size_t i = 0; i < rx.count(); ++i) {
    if (std::isfinite(rx.dudx[i]) && std::isfinite(rx.dvdx[i]) && std::isfinite(rx.dudy[i]) &&
        std::isfinite(rx.dvdy[i]))
      continue;
    const float f = rx.has_footprint ? rx.f[i] : 1.0f;
    rx.dudx[i] = rx.dvdy[i] = f;
    rx.dvdx[i] = rx.dudy[i] = 0.0f;
  }
}

void jacobian_planes(const Receivers& rx, std::vector<float>& planes) {
  const size_t n = rx.count();
  planes.resize(4 * n);
  const std::vector<float>* columns[4] = {&rx.dudx, &rx.dvdx, &rx.dudy, &rx.dvdy};
  for (size_t p = 0; p < 4; ++p)
    std::copy(columns[p]->begin(), columns[p]->begin() + long(n), planes.begin() + long(p * n));
}

void footprint_from_jacobian(Receivers& rx) {
  if (!rx.has_jacobian) return;
  rx.has_footprint = true;
  rx.f.resize(rx.count());
  for (size_t i = 0; i < rx.count(); ++i) rx.f[i] = isotropic_footprint(rx.dudx[i], rx.dvdx[i], rx.dudy[i], rx.dvdy[i]);
}

}  // namespace sf

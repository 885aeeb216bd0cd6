// ESM reference (kernels/methods/esm.clh).
#include <algorithm>
#include <cmath>

#include "methods_detail.hpp"

namespace sf::ref {

Planes esm_basis(const HostImage& depth, double c) {
  Planes out(depth.width, depth.height, 1);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) out.at(0, x, y) = std::exp(c * (depth.at(x, y) - 0.5));
  return out;
}

double esm_visibility(double filtered_basis, double d, double c) {
  return std::clamp(std::exp(-c * (d - 0.5)) * filtered_basis, 0.0, 1.0);
}

MethodRef detail::esm_ref(const std::vector<float>& p, const FilterOptions&) {
  const double c = p[0];
  MethodRef m;
  m.channels = 1;
  m.basis = [c](double z, double* b) { b[0] = std::exp(c * (z - 0.5)); };
  m.visibility = [c](const double* b, double d) { return esm_visibility(b[0], d, c); };
  return m;
}

}  // namespace sf::ref

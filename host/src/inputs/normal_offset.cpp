// The normal offset of the receivers' lookups (normal_offset.hpp).
#include "shadowfilter/normal_offset.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "shadowfilter/errors.hpp"

namespace sf {

std::array<float, 3> texel_scaled_normal(const double jacobian[3][3], const Vec3& normal) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto row = [&](int r) { return Vec3{jacobian[r][0], jacobian[r][1], jacobian[r][2]}; };
  const double texel_width = 1.0 / std::sqrt(length(row(0)) * length(row(1)));
  if (!(std::isfinite(texel_width) && texel_width > 0.0)) return {nan, nan, nan};
  const Vec3 step = texel_width * normal;
  return {float(dot(row(0), step)), float(dot(row(1), step)), float(dot(row(2), step))};
}

Receivers offset_along_normals(const Receivers& receivers, int map_width, int map_height, float texels) {
  if (!(texels >= 0.0f && texels <= kMaxNormalOffset))
    throw InputError("normal offset must be in [0, " + std::to_string(int(kMaxNormalOffset)) + "] texels, got " +
                     std::to_string(texels));
  if (!(map_width > 0 && map_height > 0)) throw InputError("normal offset: the map has no texels");
  Receivers out = receivers;
  if (!receivers.has_normal || receivers.grid || texels == 0.0f) return out;
  const size_t n = receivers.count();
  if (receivers.nx.size() != n || receivers.ny.size() != n || receivers.nz.size() != n || receivers.u.size() != n ||
      receivers.v.size() != n || receivers.d.size() != n)
    throw InputError("normal offset: the receivers' normals do not match their size");
  const float su = texels / float(map_width), sv = texels / float(map_height);
  for (size_t i = 0; i < n; ++i) {
    const float nx = receivers.nx[i], ny = receivers.ny[i], nz = receivers.nz[i];
    if (!(std::isfinite(nx) && std::isfinite(ny) && std::isfinite(nz))) continue;  // unknown normal
    out.u[i] += su * nx;
    out.v[i] += sv * ny;
    out.d[i] += texels * nz;
  }
  return out;
}

}  // namespace sf

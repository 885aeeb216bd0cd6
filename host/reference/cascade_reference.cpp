// The layered reference (cascade_reference.hpp).
#include "cascade_reference.hpp"

#include <cmath>
#include <limits>

#include "reference.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::ref {
namespace {

// sf_cascade_moved's twin: p moved `texels` of layer k's texels (1 / sqrt(|grad uW| |grad vH|)
// at p) along the camera-facing unit normal of the pixel's offsets.
Point3 moved(const CascadeSet& set, int k, const Point3& p, const Point3& dx, const Point3& dy, double texels) {
  if (texels == 0.0) return p;
  const Point3 c = cross(dx, dy);
  const double l = length(c);
  if (!(l > 0.0 && std::isfinite(l))) return p;
  Point3 du, dv;
  set.layers[size_t(k)].transform.jacobian_uv(p, du, dv);
  const double width = 1.0 / std::sqrt(set.width * length(du) * set.height * length(dv));
  const Point3 m = p + (-texels * width / l) * c;
  return std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z) ? m : p;
}

}  // namespace

CascadeProjection project_cascades(const CascadeSet& set, const ViewReceivers& view, double normal_offset) {
  const size_t count = view.count();
  const size_t K = set.layers.size();
  CascadeProjection out;
  out.choice.resize(count);
  out.layers.resize(K);
  for (Receivers& rx : out.layers) {
    rx.width = view.width;
    rx.height = view.height;
    rx.has_footprint = true;
    rx.u.assign(count, 0.0f);
    rx.v.assign(count, 0.0f);
    rx.d.assign(count, std::numeric_limits<float>::quiet_NaN());
    rx.f.assign(count, 1.0f);
    rx.has_jacobian = true;  // the identity where the layer does not serve the receiver
    rx.dudx.assign(count, 1.0f);
    rx.dvdx.assign(count, 0.0f);
    rx.dudy.assign(count, 0.0f);
    rx.dvdy.assign(count, 1.0f);
  }
  for (size_t i = 0; i < count; ++i) {
    const Point3 p{view.x[i], view.y[i], view.z[i]};
    const Point3 dx{view.dxx[i], view.dxy[i], view.dxz[i]}, dy{view.dyx[i], view.dyy[i], view.dyz[i]};
    const CascadeChoice c = select_cascade(set, view.depth[i], p);
    out.choice[i] = c;
    for (int j = 0; j < 2; ++j) {
      const int k = c.layer[j];
      if (k < 0) continue;
      const Point3 m = moved(set, k, p, dx, dy, normal_offset);
      const LayerTransform::MapPoint q = set.layers[k].transform.apply(m);
      Receivers& rx = out.layers[k];
      rx.u[i] = float(q.u);
      rx.v[i] = float(q.v);
      rx.d[i] = float(q.d);
      rx.f[i] = float(layer_footprint(set, k, m, dx, dy));
      const std::array<double, 4> jac = layer_jacobian(set, k, m, dx, dy);
      if (std::isfinite(jac[0]) && std::isfinite(jac[1]) && std::isfinite(jac[2]) && std::isfinite(jac[3])) {
        rx.dudx[i] = float(jac[0]);
        rx.dvdx[i] = float(jac[1]);
        rx.dudy[i] = float(jac[2]);
        rx.dvdy[i] = float(jac[3]);
      }
    }
  }
  return out;
}

std::vector<double> filter_cascades(const FilterOptions& options, const CascadeSet& set,
                                    const std::vector<HostImage>& maps, const CascadeProjection& projection) {
  if (maps.size() != set.layers.size() || projection.layers.size() != set.layers.size())
    throw InputError("filter_cascades: one map and one projection per layer");
  std::vector<std::vector<double>> vis;
  for (size_t k = 0; k < set.layers.size(); ++k)
    vis.push_back(filter(layer_filter_options(options, set, int(k)), maps[k], projection.layers[k]));
  std::vector<double> out(projection.choice.size(), 1.0);
  for (size_t i = 0; i < out.size(); ++i) {
    const CascadeChoice& c = projection.choice[i];
    if (c.layer[0] < 0) continue;
    out[i] = c.weight[0] * vis[c.layer[0]][i];
    if (c.layer[1] >= 0) out[i] += c.weight[1] * vis[c.layer[1]][i];
  }
  return out;
}

std::vector<double> filter_cascades(const FilterOptions& options, const CascadeSet& set,
                                    const std::vector<HostImage>& maps, const ViewReceivers& view) {
  std::vector<double> out = filter_cascades(options, set, maps, project_cascades(set, view, normal_offset(options)));
  if (options.facing_away_shadowed && !view.ndl.empty())
    for (size_t i = 0; i < out.size(); ++i)
      if (view.ndl[i] <= 0.0f && std::isfinite(view.depth[i])) out[i] = 0.0;
  return out;
}

}  // namespace sf::ref

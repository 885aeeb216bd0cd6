// Scalar reference of kernels/soft/*.cl (see soft_reference.hpp).
#include "soft_reference.hpp"

#include <algorithm>
#include <cmath>

#include "lookups.hpp"

namespace sf::ref {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool outside(double u, double v, double d) {
  return !std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v) || u < 0 || u > 1 || v < 0 || v > 1;
}

// The light's footprint (uv: u, v) in the plane of a blocker at z (soft_common.clh sf_soft_width).
// ssmm's size of a footprint (sf_soft_scale): its shorter side, at least the longer / aniso
// (ssmm 8, ssmm-improved 1.5: SF_SOFT_MAX_ANISO, SF_SSMM_IMPROVED_ANISO).
struct Sides {
  double u, v;
  double scale(double aniso) const { return std::max(std::min(u, v), std::max(u, v) / aniso); }
};
double ssmm_aniso(const SoftOptions& o) { return o.method == SoftMethod::SsmmImproved ? 1.5 : 8.0; }
Sides soft_sides(const SoftLight& L, double d, double z) { return {soft_width(L, d, z), soft_height(L, d, z)}; }

// Kernel sides in texels: each at least the footprint's side and one texel, at most `cap`
// (sf_soft_texels).
Sides texels(const Sides& w, int W, int H, const SoftFootprint& fp, double cap) {
  return {std::clamp(std::max(w.u * W, fp.u), 1.0, cap), std::clamp(std::max(w.v * H, fp.v), 1.0, cap)};
}

// The light's sides over that size (sf_soft_shape).
Sides shape(const SoftLight& L, double aniso) {
  const double a = L.size, b = light_height(L), k = Sides{a, b}.scale(aniso);
  return k > 0 ? Sides{a / k, b / k} : Sides{1.0, 1.0};
}

}  // namespace

SoftFootprint soft_footprint(double f) {
  const double s = std::isfinite(f) ? f : 1.0;
  return {s, s};
}

SoftFootprint soft_footprint(const Receivers& rx, size_t i) {
  if (rx.grid || !rx.has_footprint) return {};
  if (!rx.has_jacobian) return soft_footprint(rx.f[i]);
  const double u = std::fabs(double(rx.dudx[i])) + std::fabs(double(rx.dudy[i]));
  const double v = std::fabs(double(rx.dvdx[i])) + std::fabs(double(rx.dvdy[i]));
  return std::isfinite(u) && std::isfinite(v) ? SoftFootprint{u, v} : SoftFootprint{};
}

BoxScan box_scan(const double* img, int w, int h, double u, double v, double wx, double wy, const Plane& p,
                 double bias) {
  const double cx = u * w, cy = v * h, hx = 0.5 * wx, hy = 0.5 * wy;
  const double x0 = cx - hx, x1 = cx + hx, y0 = cy - hy, y1 = cy + hy;
  double W = 0, lit = 0, blk = 0, blkz = 0;
  for (int j = int(std::floor(y0)); j <= int(std::ceil(y1)) - 1; ++j) {
    const double wy = std::min(y1, j + 1.0) - std::max(y0, double(j));
    if (wy <= 0) continue;
    const int tj = std::clamp(j, 0, h - 1);
    const double* row = img + size_t(tj) * w;
    for (int i = int(std::floor(x0)); i <= int(std::ceil(x1)) - 1; ++i) {
      const double wx = std::min(x1, i + 1.0) - std::max(x0, double(i));
      if (wx <= 0) continue;
      const int ti = std::clamp(i, 0, w - 1);
      const double z = row[ti], wt = wx * wy;
      W += wt;
      if (z >= p.at(ti, tj) - bias)
        lit += wt;
      else {
        blk += wt;
        blkz += wt * z;
      }
    }
  }
  BoxScan r;
  r.lit = lit / W;
  r.blk = blk / W;
  r.zavg = blk > 0 ? blkz / blk : NAN;
  return r;
}

Plane plane_level(const Plane& p, int W, int H, int w, int h) {
  const double sx = double(W) / w, sy = double(H) / h;
  Plane q;
  q.x = (p.x + 0.5) / sx - 0.5;
  q.y = (p.y + 0.5) / sy - 0.5;
  q.gx = p.gx * sx;
  q.gy = p.gy * sy;
  q.d = p.d - 0.5 * (std::abs(p.gx) * (sx - 1) + std::abs(p.gy) * (sy - 1));
  return q;
}

double soft_horizon(const SoftOptions& o, const Plane& pl, int W, int H) {
  const SoftLight& L = o.light;
  const double unit = soft_side_scale(L);
  const SoftDistance D = soft_distance(L);
  const double a = D.a, b = D.b;
  const double Ax = pl.gx * W * L.size * unit, Ay = pl.gy * H * light_height(L) * unit, A = std::hypot(Ax, Ay);
  const double DR = std::max(a + b * pl.d, 1e-20);
  const double s = L.perspective ? b / (DR * DR) : b / DR;
  if (!(A > 0) || !(s > 0)) return 1.0;
  const double t = -1.0 / (s * A);
  double p = 0.5 * std::abs(Ax) / A, q = 0.5 * std::abs(Ay) / A;
  if (q > p) std::swap(p, q);
  double below;
  if (t <= -(p + q))
    below = 0;
  else if (t >= p + q)
    below = 1;
  else if (q < 1e-6 * p)
    below = (t + p) / (2 * p);
  else if (t <= q - p)
    below = (t + p + q) * (t + p + q) / (8 * p * q);
  else if (t <= p - q)
    below = (t + p) / (2 * p);
  else
    below = 1 - (p + q - t) * (p + q - t) / (8 * p * q);
  return std::clamp(1 - below, 0.0, 1.0);
}

double soft_pcss(const Planes& depth, const SoftOptions& o, double u, double v, const Plane& plane,
                 const SoftFootprint& fp) {
  if (outside(u, v, plane.d)) return 1.0;
  const double d = plane.d, bias = plane.bias(o.bias, o.receiver_plane.slope_bias);
  const int W = depth.width, H = depth.height;
  const double* img = depth.data.data();
  const Sides search = texels(soft_sides(o.light, d, 0.0), W, H, SoftFootprint{}, o.max_width);
  const double horizon = soft_horizon(o, plane, W, H);
  const BoxScan s = box_scan(img, W, H, u, v, search.u, search.v, plane, bias);
  if (!(s.blk > 0)) return horizon;
  const Sides width = texels(soft_sides(o.light, d, s.zavg), W, H, fp, o.max_width);
  return box_scan(img, W, H, u, v, width.u, width.v, plane, bias).lit * horizon;
}

double soft_ssmm(const std::vector<Planes>& chain, const SoftOptions& o, double u, double v, const Plane& plane,
                 const SoftFootprint& fp) {
  if (outside(u, v, plane.d)) return 1.0;
  const double d = plane.d, bias = plane.bias(o.bias, o.receiver_plane.slope_bias);
  const int top = int(chain.size()) - 1, W = chain[0].width, H = chain[0].height;
  const double n = o.ssmm.n;
  const Sides search2 = soft_sides(o.light, d, 0.0);
  const double aniso = ssmm_aniso(o);
  const double search = search2.scale(aniso);
  const Sides box = shape(o.light, aniso);  // a layer's box: n x n of the light's shape (texels of x)
  const double horizon = soft_horizon(o, plane, W, H);
  int last = 0;
  while (last < top && n * double(1 << last) / W < search) ++last;
  if (o.method == SoftMethod::SsmmImproved) {
    double sb = 0;
    for (int k = 0; k <= last; ++k) {
      const Planes& P = chain[k];
      const int w = P.width, h = P.height;
      const Plane pk = plane_level(plane, W, H, w, h);
      const double ri = n / w, rlo = 0.5 * ri, rhi = 2 * ri;
      const double cx = u * w, cy = v * h, hx = 0.5 * n * box.u, hy = 0.5 * n * box.v * h / w;
      const double x0 = cx - hx, x1 = cx + hx, y0 = cy - hy, y1 = cy + hy;
      double acc = 0, ws = 0;
      for (int j = int(std::floor(y0)); j <= int(std::ceil(y1)) - 1; ++j) {
        const double wy = std::min(y1, j + 1.0) - std::max(y0, double(j));
        if (wy <= 0) continue;
        for (int i = int(std::floor(x0)); i <= int(std::ceil(x1)) - 1; ++i) {
          const double wx = std::min(x1, i + 1.0) - std::max(x0, double(i));
          if (wx <= 0) continue;
          ws += wx * wy;
          const int ti = std::clamp(i, 0, w - 1), tj = std::clamp(j, 0, h - 1);
          const double z = P.at(0, ti, tj);
          if (!(z < pk.at(ti, tj) - bias)) continue;
          const double r = soft_sides(o.light, d, z).scale(aniso);
          double wt;
          if (r <= ri)
            wt = k == 0 ? 1.0 : std::max((r - rlo) / (ri - rlo), 0.0);
          else
            wt = k == top ? 1.0 : std::max((rhi - r) / (rhi - ri), 0.0);
          acc += wx * wy * wt;
        }
      }
      sb += acc / ws;
    }
    return std::clamp(1.0 - sb, 0.0, 1.0) * horizon;
  }
  const Planes& S = chain[last];
  const BoxScan s = box_scan(S.data.data(), S.width, S.height, u, v, std::max(search2.u * S.width, 1.0),
                             std::max(search2.v * S.height, 1.0), plane_level(plane, W, H, S.width, S.height), bias);
  if (!(s.blk > 0)) return horizon;
  const Sides r2 = soft_sides(o.light, d, s.zavg);
  const double r = r2.scale(aniso), r0 = n / W;
  if (r < r0) {
    // At most layer 0's box (n texels times the light's shape), at least one texel.
    const Sides width{std::clamp(std::max(r2.u * W, fp.u), 1.0, std::max(n * box.u, 1.0)),
                      std::clamp(std::max(r2.v * H, fp.v), 1.0, std::max(n * box.v * H / W, 1.0))};
    return box_scan(chain[0].data.data(), W, H, u, v, width.u, width.v, plane, bias).lit * horizon;
  }
  const int a = std::min(int(std::floor(std::log2(r / r0))), top);
  const double ra = r0 * double(1 << a);
  const double wb = a >= top ? 0.0 : std::clamp((r - ra) / ra, 0.0, 1.0);
  double res = 0;
  for (int t = 0; t < 2; ++t) {
    const double wt = t == 0 ? 1 - wb : wb;
    if (wt <= 0) continue;
    const Planes& P = chain[a + t];
    res += wt * box_scan(P.data.data(), P.width, P.height, u, v, n * box.u, n * box.v * P.height / P.width,
                         plane_level(plane, W, H, P.width, P.height), bias)
                    .lit;
  }
  return std::clamp(res, 0.0, 1.0) * horizon;
}

Planes cssm_basis(const HostImage& depth, int M, Storage storage) {
  Planes p(depth.width, depth.height, 4 * M + 1);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      const double z = depth.at(x, y);
      for (int k = 0; k < M; ++k) {
        const double ck = (2 * k + 1) * kPi;
        p.at(k, x, y) = std::sin(ck * z);
        p.at(M + k, x, y) = std::cos(ck * z);
        p.at(2 * M + k, x, y) = z * std::sin(ck * z);
        p.at(3 * M + k, x, y) = z * std::cos(ck * z);
      }
      p.at(4 * M, x, y) = 0.5 * z;
    }
  if (storage_unorm(storage))
    for (double& b : p.data) b = 0.5 + 0.5 * b;
  quantise(p, storage);
  return p;
}

namespace {
double series(const std::vector<double>& b, int M, double dp, double* num) {
  double sf = 0, sz = 0;
  for (int k = 0; k < M; ++k) {
    const double ck = (2 * k + 1) * kPi, s = std::sin(ck * dp), c = std::cos(ck * dp);
    sf += (c * b[k] - s * b[M + k]) / ck;
    sz += (s * b[3 * M + k] - c * b[2 * M + k]) / ck;
  }
  if (num) *num = b[4 * M] + 2 * sz;
  return 0.5 + 2 * sf;
}
}  // namespace

double soft_cssm(const LookupRef& basis, int W, int H, const SoftOptions& o, double u, double v, double d,
                 const SoftFootprint& fp, double* zavg_out) {
  if (zavg_out) *zavg_out = NAN;
  if (outside(u, v, d)) return 1.0;
  d = std::clamp(d, 0.0, 1.0);
  const int M = o.cssm.order;
  const CssmParams P = cssm_params(o);
  const double dp = d - P.offset;
  std::vector<double> b(4 * M + 1);
  const Sides search = texels(soft_sides(o.light, d, 0.0), W, H, fp, o.max_width);
  const bool unorm = storage_unorm(o.cssm.storage);
  // Mean over fx x fy texels (cssm.cl sf_cssm_lookup): the SAT's rectangle, or the mips'
  // anisotropic probes, n = ceil(long / short) (ratios within 1% of 1: one; at most 8) at the
  // centres of n equal parts of the long side, each at the LOD of 0.55 max(short, long / n).
  auto read = [&](int c, const Sides& fw) {
    double x = 0;
    if (o.cssm.lookup == Lookup::Sat) {
      x = basis.box(c, u, v, fw.u, fw.v);
    } else {
      const double lo = std::min(fw.u, fw.v), hi = std::max(fw.u, fw.v);
      const int n = std::clamp(int(std::ceil(hi / lo - 0.01)), 1, 8);
      const double step = hi / n;
      for (int j = 0; j < n; ++j) {
        const double off = (j + 0.5 - 0.5 * n) * step;
        const bool along_u = fw.u >= fw.v;
        x += basis.value(c, along_u ? u + off / W : u, along_u ? v : v + off / H, 0.55 * std::max(lo, step)) / n;
      }
    }
    return unorm ? 2.0 * x - 1.0 : x;
  };
  for (int c = 0; c <= 4 * M; ++c) b[c] = read(c, search);
  double num;
  const double den = 1.0 - series(b, M, d - P.z_offset, &num);
  const bool blocked = den >= o.cssm.min_den;
  if (!blocked && !o.cssm.contact) return 1.0;
  const double zavg = blocked ? std::clamp(num / den, 0.0, d) : d;
  if (zavg_out && blocked) *zavg_out = zavg;
  const Sides s2 = soft_sides(o.light, d, zavg);
  const Sides fw = texels({P.width_scale * s2.u, P.width_scale * s2.v}, W, H, fp, o.max_width);
  for (int c = 0; c < 2 * M; ++c) b[c] = read(c, fw);
  double vis =
      std::clamp(0.5 + P.scale * (series(b, M, dp, nullptr) / (o.cssm.normalise ? P.lit : 1.0) - 0.5), 0.0, 1.0);
  if (P.sharpen_a > 0) vis = std::pow(vis, 1.0 + P.sharpen_a * std::exp(-P.sharpen_b * (d - zavg)));
  return vis;
}

}  // namespace sf::ref

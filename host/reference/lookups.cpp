#include "lookups.hpp"

#include "receiver_plane.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sf::ref {
namespace {

int clampi(int v, int lo, int hi) { return std::min(std::max(v, lo), hi); }

double reduce(int op, double a, double b, double c, double d) {
  if (op == 1) return std::max(std::max(a, b), std::max(c, d));
  if (op == 2) return std::min(std::min(a, b), std::min(c, d));
  return 0.25 * ((a + b) + (c + d));
}

bool outside(double u, double v, double d) {
  return !std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v) || u < 0 || u > 1 || v < 0 || v > 1;
}

// The kernels' texel coordinate u n - 1/2, rounded once to float32 (see reference.cpp).
double texel_coordinate(double u, int n) { return double(float(u * n - 0.5)); }

// A dense window of weights over texels [x0, x0 + w) x [y0, y0 + h).
struct Window {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<double> v;
  Window(int x0_, int y0_, int x1, int y1)
      : x0(x0_), y0(y0_), w(x1 - x0_ + 1), h(y1 - y0_ + 1), v(size_t(w) * h, 0.0) {}
  double& at(int x, int y) { return v[size_t(y - y0) * w + (x - x0)]; }
};

// Bilinear taps of a W x H level at (u, v), scaled by `scale`, added into a window covering them.
Window bilinear_window(int W, int H, double u, double v, double scale) {
  const double x = texel_coordinate(u, W), y = texel_coordinate(v, H);
  const double xf = std::floor(x), yf = std::floor(y);
  const int xs[2] = {clampi(int(xf), 0, W - 1), clampi(int(xf) + 1, 0, W - 1)};
  const int ys[2] = {clampi(int(yf), 0, H - 1), clampi(int(yf) + 1, 0, H - 1)};
  const double wx[2] = {1 - (x - xf), x - xf}, wy[2] = {1 - (y - yf), y - yf};
  Window win(std::min(xs[0], xs[1]), std::min(ys[0], ys[1]), std::max(xs[0], xs[1]), std::max(ys[0], ys[1]));
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) win.at(xs[i], ys[j]) += scale * wx[i] * wy[j];
  return win;
}

// Adjoint of one mean reduction: weights on level k (size of level k-1 given) -> level k-1.
Window push_down(const Window& in, int Wp, int Hp) {
  Window out(2 * in.x0, 2 * in.y0, std::min(2 * (in.x0 + in.w - 1) + 1, Wp - 1),
             std::min(2 * (in.y0 + in.h - 1) + 1, Hp - 1));
  for (int j = 0; j < in.h; ++j)
    for (int i = 0; i < in.w; ++i) {
      const double w = in.v[size_t(j) * in.w + i];
      if (w == 0) continue;
      const int x = in.x0 + i, y = in.y0 + j;
      const int xa = 2 * x, xb = std::min(2 * x + 1, Wp - 1), ya = 2 * y, yb = std::min(2 * y + 1, Hp - 1);
      out.at(xa, ya) += 0.25 * w;
      out.at(xb, ya) += 0.25 * w;
      out.at(xa, yb) += 0.25 * w;
      out.at(xb, yb) += 0.25 * w;
    }
  return out;
}

void add_into(Window& dst, const Window& src) {
  for (int j = 0; j < src.h; ++j)
    for (int i = 0; i < src.w; ++i) dst.at(src.x0 + i, src.y0 + j) += src.v[size_t(j) * src.w + i];
}

// Box corners as the kernel rounds them.
void box_corners(double u, double v, double fx, double fy, int W, int H, double& X0, double& X1, double& Y0,
                 double& Y1) {
  const float sx = 0.5f * (std::isfinite(fx) ? std::max(float(fx), 1.0f) : 1.0f);
  const float sy = 0.5f * (std::isfinite(fy) ? std::max(float(fy), 1.0f) : 1.0f);
  X0 = std::fmaf(float(u), float(W), -sx);
  X1 = std::fmaf(float(u), float(W), sx);
  Y0 = std::fmaf(float(v), float(H), -sy);
  Y1 = std::fmaf(float(v), float(H), sy);
}

double overlap(int i, double a, double b) { return std::max(0.0, std::min(i + 1.0, b) - std::max(double(i), a)); }

// Level-0 weights of the lookup (before the blur): mips at footprint f, the box over fx x fy.
Window level0_window(int W, int H, Lookup kind, double u, double v, double f, double fx, double fy) {
  if (kind == Lookup::Bilinear) return bilinear_window(W, H, u, v, 1.0);
  if (kind == Lookup::Sat) {
    double X0, X1, Y0, Y1;
    box_corners(u, v, fx, fy, W, H, X0, X1, Y0, Y1);
    const int ia = int(std::floor(X0)), ib = int(std::ceil(X1)) - 1;
    const int ja = int(std::floor(Y0)), jb = int(std::ceil(Y1)) - 1;
    Window win(clampi(ia, 0, W - 1), clampi(ja, 0, H - 1), clampi(ib, 0, W - 1), clampi(jb, 0, H - 1));
    const double area = (X1 - X0) * (Y1 - Y0);
    for (int j = ja; j <= jb; ++j)
      for (int i = ia; i <= ib; ++i)
        win.at(clampi(i, 0, W - 1), clampi(j, 0, H - 1)) += overlap(i, X0, X1) * overlap(j, Y0, Y1) / area;
    return win;
  }
  // Trilinear: each level's bilinear weights pushed down to level 0.
  std::vector<std::pair<int, int>> sizes{{W, H}};
  while (sizes.back().first > 1 || sizes.back().second > 1)
    sizes.push_back({(sizes.back().first + 1) / 2, (sizes.back().second + 1) / 2});
  double t;
  const int k0 = lod(f, int(sizes.size()) - 1, t);
  auto level = [&](int k, double scale) {
    Window win = bilinear_window(sizes[k].first, sizes[k].second, u, v, scale);
    for (int j = k; j > 0; --j) win = push_down(win, sizes[j - 1].first, sizes[j - 1].second);
    return win;
  };
  Window a = level(k0, 1 - t);
  if (t <= 0) return a;
  Window b = level(k0 + 1, t);  // covers a's window (a coarser level's support contains it)
  Window out(std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x0 + a.w, b.x0 + b.w) - 1,
             std::max(a.y0 + a.h, b.y0 + b.h) - 1);
  add_into(out, a);
  add_into(out, b);
  return out;
}

}  // namespace

std::vector<Planes> mip_chain(const Planes& level0, int op) {
  std::vector<Planes> chain{level0};
  while (chain.back().width > 1 || chain.back().height > 1) {
    const Planes& p = chain.back();
    Planes n((p.width + 1) / 2, (p.height + 1) / 2, p.channels);
    for (int c = 0; c < p.channels; ++c)
      for (int j = 0; j < n.height; ++j)
        for (int i = 0; i < n.width; ++i) {
          const int xa = 2 * i, xb = std::min(2 * i + 1, p.width - 1);
          const int ya = 2 * j, yb = std::min(2 * j + 1, p.height - 1);
          n.at(c, i, j) = reduce(op, p.at(c, xa, ya), p.at(c, xb, ya), p.at(c, xa, yb), p.at(c, xb, yb));
        }
    chain.push_back(std::move(n));
  }
  return chain;
}

Planes sat_table(const Planes& img) {
  Planes S(img.width + 1, img.height + 1, img.channels);
  for (int c = 0; c < img.channels; ++c)
    for (int y = 0; y < img.height; ++y) {
      double row = 0;
      for (int x = 0; x < img.width; ++x) {
        row += img.at(c, x, y);
        S.at(c, x + 1, y + 1) = S.at(c, x + 1, y) + row;
      }
    }
  return S;
}

double footprint_at(const Receivers& rx, size_t i) {
  return (!rx.grid && rx.has_footprint && i < rx.f.size()) ? double(rx.f[i]) : 1.0;
}

FootprintProbes isotropic_probe(double f) {
  FootprintProbes p;
  p.f = p.fx = p.fy = float(f);
  return p;
}

FootprintProbes probes_at(const Receivers& rx, size_t i, int max_anisotropy) {
  if (rx.grid || !rx.has_jacobian || max_anisotropy <= 1 || i >= rx.dudx.size())
    return isotropic_probe(footprint_at(rx, i));
  return footprint_probes(rx.dudx[i], rx.dvdx[i], rx.dudy[i], rx.dvdy[i], max_anisotropy);
}

void probe_uv(const FootprintProbes& p, int k, int W, int H, double u, double v, double& uk, double& vk) {
  const float o = p.offset(k);
  uk = double(float(u) + (o * p.du) / float(W));
  vk = double(float(v) + (o * p.dv) / float(H));
}

int lod(double f, int top, double& t) {
  const float ff = std::isfinite(f) ? std::max(float(f), 1.0f) : 1.0f;
  const float l = std::log2(ff);
  int k0 = int(std::floor(l));
  t = double(l - float(k0));
  if (k0 >= top) {
    k0 = top;
    t = 0;
  }
  return k0;
}

double trilinear(const std::vector<Planes>& chain, int c, double u, double v, double f) {
  double t;
  const int k0 = lod(f, int(chain.size()) - 1, t);
  const double a = bilinear(chain[k0], c, u, v);
  if (t <= 0) return a;
  return (1 - t) * a + t * bilinear(chain[k0 + 1], c, u, v);
}

double box_mean(const Planes& img, int c, double u, double v, double f) { return box_mean(img, c, u, v, f, f); }

double box_mean(const Planes& img, int c, double u, double v, double fx, double fy) {
  double X0, X1, Y0, Y1;
  box_corners(u, v, fx, fy, img.width, img.height, X0, X1, Y0, Y1);
  double acc = 0;
  for (int j = int(std::floor(Y0)); j <= int(std::ceil(Y1)) - 1; ++j) {
    const double cy = overlap(j, Y0, Y1);
    double row = 0;
    for (int i = int(std::floor(X0)); i <= int(std::ceil(X1)) - 1; ++i)
      row += overlap(i, X0, X1) * img.at(c, clampi(i, 0, img.width - 1), clampi(j, 0, img.height - 1));
    acc += cy * row;
  }
  return acc / ((X1 - X0) * (Y1 - Y0));
}

LookupRef::LookupRef(const Planes& filtered, Lookup kind, Storage storage) : kind_(kind) {
  if (kind == Lookup::Mips) {
    chain_ = mip_chain(filtered, 0);
    for (size_t k = 1; k < chain_.size(); ++k) quantise(chain_[k], storage);
  } else {
    chain_.push_back(filtered);
  }
}

LookupRef::LookupRef(const Planes& filtered, Lookup kind, const std::vector<Storage>& plane_storage)
    : LookupRef(filtered, kind, Storage::F32) {
  if (plane_storage.size() != size_t(filtered.channels))
    throw std::invalid_argument("LookupRef: one storage per plane");
  for (size_t k = 1; k < chain_.size(); ++k) {
    Planes& level = chain_[k];
    const size_t plane = size_t(level.width) * level.height;
    for (int c = 0; c < level.channels; ++c)
      for (size_t i = 0; i < plane; ++i)
        level.data[c * plane + i] = quantise(level.data[c * plane + i], plane_storage[c]);
  }
}

double LookupRef::value(int c, double u, double v, double f) const {
  switch (kind_) {
    case Lookup::Mips:
      return trilinear(chain_, c, u, v, f);
    case Lookup::Sat:
      return box_mean(chain_[0], c, u, v, f);
    default:
      return bilinear(chain_[0], c, u, v);
  }
}

double LookupRef::value(int c, double u, double v, const FootprintProbes& p) const {
  if (kind_ == Lookup::Bilinear) return bilinear(chain_[0], c, u, v);
  const Planes& level0 = chain_[0];
  double acc = 0;
  for (int k = 0; k < p.n; ++k) {
    double uk, vk;
    probe_uv(p, k, level0.width, level0.height, u, v, uk, vk);
    acc += kind_ == Lookup::Mips ? trilinear(chain_, c, uk, vk, p.f) : box_mean(level0, c, uk, vk, p.fx, p.fy);
  }
  return acc / p.n;
}

double LookupRef::box(int c, double u, double v, double fx, double fy) const {
  return box_mean(chain_[0], c, u, v, fx, fy);
}

namespace {
// The blur's taps around a level-0 window.
std::vector<Tap> blurred_taps(int W, int H, const BlurOptions& blur_opt, const Window& l0) {
  const int R = blur_opt.radius;
  const auto g = gaussian_weights(R, blur_opt.sigma);
  Window out(std::max(l0.x0 - R, 0), std::max(l0.y0 - R, 0), std::min(l0.x0 + l0.w - 1 + R, W - 1),
             std::min(l0.y0 + l0.h - 1 + R, H - 1));
  for (int j = 0; j < l0.h; ++j)
    for (int i = 0; i < l0.w; ++i) {
      const double w = l0.v[size_t(j) * l0.w + i];
      if (w == 0) continue;
      for (int b = -R; b <= R; ++b)
        for (int a = -R; a <= R; ++a)
          out.at(clampi(l0.x0 + i + a, 0, W - 1), clampi(l0.y0 + j + b, 0, H - 1)) +=
              w * g[std::abs(a)] * g[std::abs(b)];
    }
  std::vector<Tap> taps;
  for (int j = 0; j < out.h; ++j)
    for (int i = 0; i < out.w; ++i)
      if (out.v[size_t(j) * out.w + i] != 0) taps.push_back({out.x0 + i, out.y0 + j, out.v[size_t(j) * out.w + i]});
  return taps;
}
}  // namespace

std::vector<Tap> lookup_taps(int W, int H, const BlurOptions& blur_opt, Lookup kind, double u, double v, double f) {
  return blurred_taps(W, H, blur_opt, level0_window(W, H, kind, u, v, f, f, f));
}

std::vector<Tap> lookup_taps(int W, int H, const BlurOptions& blur_opt, Lookup kind, double u, double v,
                             const FootprintProbes& p) {
  std::vector<Window> parts;
  int x0 = W, y0 = H, x1 = -1, y1 = -1;
  for (int k = 0; k < p.n; ++k) {
    double uk, vk;
    probe_uv(p, k, W, H, u, v, uk, vk);
    parts.push_back(level0_window(W, H, kind, uk, vk, p.f, p.fx, p.fy));
    const Window& w = parts.back();
    x0 = std::min(x0, w.x0), y0 = std::min(y0, w.y0);
    x1 = std::max(x1, w.x0 + w.w - 1), y1 = std::max(y1, w.y0 + w.h - 1);
  }
  Window all(x0, y0, x1, y1);
  for (Window& w : parts) {
    for (double& x : w.v) x /= p.n;
    add_into(all, w);
  }
  return blurred_taps(W, H, blur_opt, all);
}

double s_ref(const HostImage& depth, const BlurOptions& blur_opt, Lookup kind, double u, double v, const Plane& plane,
             const FootprintProbes& probes, double bias) {
  if (outside(u, v, plane.d)) return 1.0;
  double acc = 0;
  for (const Tap& t : lookup_taps(depth.width, depth.height, blur_opt, kind, u, v, probes))
    if (depth.at(t.x, t.y) - plane.at(t.x, t.y) + bias >= 0) acc += t.w;
  return acc;
}

double s_ref(const HostImage& depth, const BlurOptions& blur_opt, Lookup kind, double u, double v, double d, double f,
             double bias) {
  if (outside(u, v, d)) return 1.0;  // before the clamp, which would make an infinite d finite
  return s_ref(depth, blur_opt, kind, u, v, flat_plane(depth.width, depth.height, u, v, std::clamp(d, 0.0, 1.0)), f,
               bias);
}

double s_ref(const HostImage& depth, const BlurOptions& blur_opt, Lookup kind, double u, double v, const Plane& plane,
             double f, double bias) {
  if (outside(u, v, plane.d)) return 1.0;
  double acc = 0;
  for (const Tap& t : lookup_taps(depth.width, depth.height, blur_opt, kind, u, v, f))
    if (depth.at(t.x, t.y) - plane.at(t.x, t.y) + bias >= 0) acc += t.w;
  return acc;
}

std::vector<double> s_ref(const HostImage& depth, const BlurOptions& blur_opt, Lookup kind, const Receivers& rx) {
  std::vector<double> out(rx.count(), 1.0);
  for (size_t i = 0; i < rx.count(); ++i) {
    const double d = rx.d[i];
    double u, v;
    if (rx.grid) {
      u = texel_centre(int(i % rx.width), rx.width);
      v = texel_centre(int(i / rx.width), rx.height);
    } else {
      u = rx.u[i];
      v = rx.v[i];
    }
    out[i] = s_ref(depth, blur_opt, kind, u, v, d, footprint_at(rx, i));
  }
  return out;
}

}  // namespace sf::ref

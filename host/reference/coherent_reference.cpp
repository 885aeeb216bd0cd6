#include "shadowfilter/vec3.hpp"
#include "coherent_reference.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "shadowfilter/errors.hpp"

namespace sf::ref::coherent {

using namespace sf::coherent;

namespace {
// z2 with kNoSurface read as +infinity.
uint32_t upper(uint16_t z2) { return z2 == kNoSurface ? 65536u : z2; }

constexpr double kPi = 3.14159265358979323846;

double lerp(double a, double b, double f) { return a + f * (b - a); }

// The 2x2 texels nearest to p in view g: project()'s geometry without the floor (continuous
// u M - 1/2, v M - 1/2, the same clamp to [-1, 2] and the same quantised depth q); (x, y) the
// lower texel, (fx, fy) the bilinear fractions.
struct TexelCell {
  int x, y;
  double fx, fy;
  uint32_t q;
};
TexelCell texel_cell(const StackLayout& l, uint32_t g, const Vec3& p) {
  const ViewFrame f = view_frame(l, g);
  const Vec3 r{p[0] - l.center[0], p[1] - l.center[1], p[2] - l.center[2]};
  auto dot = [&](const Vec3& a) { return r[0] * a[0] + r[1] * a[1] + r[2] * a[2]; };
  const double scale = 1.0 / (2.0 * l.radius);
  const double u = std::clamp(dot(f.right) * scale + 0.5, -1.0, 2.0) * l.resolution - 0.5;
  const double v = std::clamp(dot(f.up) * scale + 0.5, -1.0, 2.0) * l.resolution - 0.5;
  const uint32_t q =
      uint32_t(std::clamp(std::nearbyint((l.radius - dot(f.dir)) * scale * kDepthMax), 0.0, double(kDepthMax)));
  const double x0 = std::floor(u), y0 = std::floor(v);
  return {int(x0), int(y0), u - x0, v - y0, q};
}

// Texel (x, y) of view g lit at depth q; outside the map lit.
bool texel_lit(const CompressedStack& c, const std::vector<uint32_t>& positions, uint32_t g, int x, int y, uint32_t q) {
  const int m = c.layout.resolution;
  if (x < 0 || y < 0 || x >= m || y >= m) return true;
  return compressed_lit(c, positions[g], size_t(y) * m + x, q);
}

// Bilinear PCF of the 2x2 texels nearest to p in view g.
double texels_bilinear(const CompressedStack& c, const std::vector<uint32_t>& positions, uint32_t g, const Vec3& p) {
  const TexelCell t = texel_cell(c.layout, g, p);
  auto lit = [&](int dx, int dy) { return texel_lit(c, positions, g, t.x + dx, t.y + dy, t.q) ? 1.0 : 0.0; };
  return lerp(lerp(lit(0, 0), lit(1, 0), t.fx), lerp(lit(0, 1), lit(1, 1), t.fx), t.fy);
}

// The 2x2 views nearest to direction d in continuous lat-long coordinates: rows j0, j1 (row
// t / pi T - 1/2 clamped to [0, T - 1]), columns k0, k1 (p / (2 pi) P - 1/2, wrapping around),
// and the bilinear fractions.
struct ViewCell {
  int j0, j1, k0, k1;
  double fy, fx;
};
ViewCell view_cell(const StackLayout& l, const Vec3& d) {
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double t = std::acos(std::clamp(d[1] / n, -1.0, 1.0));
  double ph = std::atan2(d[2], d[0]);
  if (ph < 0.0) ph += 2.0 * kPi;
  const double rows = std::clamp(t / kPi * l.views_theta - 0.5, 0.0, double(l.views_theta - 1));
  const double cols = ph / (2.0 * kPi) * l.views_phi - 0.5;
  const int j0 = std::min(int(rows), l.views_theta - 1), j1 = std::min(j0 + 1, l.views_theta - 1);
  const double c0 = std::floor(cols);
  const int k0 = (int(c0) + l.views_phi) % l.views_phi, k1 = (k0 + 1) % l.views_phi;
  return {j0, j1, k0, k1, rows - j0, cols - c0};
}
}  // namespace

StreamingFit::StreamingFit(const StackLayout& layout)
    : layout_(layout), lo_(layout.texels()), hi_(layout.texels()), runs_(layout.texels()) {
  validate(layout);
}

void StreamingFit::add(const uint16_t* z1s, const uint16_t* z2s, uint32_t count) {
  const size_t texels = layout_.texels();
  if (count > uint32_t(layout_.views()) - next_)
    throw InputError("the segment fit was given map " + std::to_string(next_ + count - 1) + " of a stack of " +
                     std::to_string(layout_.views()));
  // Every texel's run is grown map by map in sequence order (each map is read once, in memory
  // order): a map that leaves no separating depth closes the run before it and starts the next.
  for (uint32_t k = 0; k < count; ++k, ++next_) {
    const uint16_t* z1 = z1s + size_t(k) * texels;
    const uint16_t* z2 = z2s + size_t(k) * texels;
    if (next_ == 0) {
      for (size_t t = 0; t < texels; ++t) {
        lo_[t] = z1[t];
        hi_[t] = upper(z2[t]);
      }
      continue;
    }
    for (size_t t = 0; t < texels; ++t) {
      const uint32_t l2 = std::max(lo_[t], uint32_t(z1[t])), h2 = std::min(hi_[t], upper(z2[t]));
      if (l2 < h2) {
        lo_[t] = l2;
        hi_[t] = h2;
        continue;
      }
      runs_[t].push_back(uint64_t((lo_[t] + hi_[t]) / 2) << 32 | (next_ - 1));
      lo_[t] = z1[t];
      hi_[t] = upper(z2[t]);
    }
  }
}

CompressedStack StreamingFit::finish() {
  const size_t texels = layout_.texels();
  const uint32_t n = uint32_t(layout_.views());
  if (next_ != n)
    throw InputError("the segment fit has " + std::to_string(next_) + " of the stack's " + std::to_string(n) + " maps");
  CompressedStack c;
  c.layout = layout_;
  c.offsets.assign(texels + 1, 0);
  size_t total = texels;
  for (const auto& r : runs_) total += r.size();
  if (total > 0xffffffffu)
    throw InputError("the stack has " + std::to_string(total) + " segments, more than 32-bit offsets address");
  c.last.reserve(total);
  c.depth.reserve(total);
  for (size_t t = 0; t < texels; ++t) {
    c.offsets[t] = uint32_t(c.last.size());
    for (uint64_t r : runs_[t]) {
      c.last.push_back(uint32_t(r));
      c.depth.push_back(uint16_t(r >> 32));
    }
    std::vector<uint64_t>().swap(runs_[t]);  // freed as they are copied: the peak is one copy
    c.last.push_back(n - 1);
    c.depth.push_back(uint16_t((lo_[t] + hi_[t]) / 2));
  }
  c.offsets[texels] = uint32_t(c.last.size());
  return c;
}

CompressedStack compress(const DualDepthStack& s) {
  StreamingFit fit(s.layout);
  fit.add(s.z1.data(), s.z2.data(), uint32_t(s.layout.views()));
  return fit.finish();
}

uint16_t segment_depth(const CompressedStack& c, size_t texel, uint32_t i) {
  uint32_t lo = c.offsets[texel], hi = c.offsets[texel + 1] - 1;  // the answer is in [lo, hi]
  while (lo < hi) {
    const uint32_t mid = (lo + hi) / 2;
    if (c.last[mid] < i)
      lo = mid + 1;
    else
      hi = mid;
  }
  return c.depth[lo];
}

int stack_test(const DualDepthStack& s, uint32_t i, size_t texel, uint32_t q) {
  const size_t at = size_t(i) * s.layout.texels() + texel;
  if (q <= s.z1[at]) return 1;
  if (q >= upper(s.z2[at])) return 0;
  return -1;
}

bool compressed_lit(const CompressedStack& c, uint32_t i, size_t texel, uint32_t q) {
  return q <= segment_depth(c, texel, i);
}

double visibility(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p, const Vec3& d) {
  const uint32_t g = view_of_direction(c.layout, d);
  const ViewPoint vp = project(c.layout, g, p);
  if (!vp.inside(c.layout.resolution)) return 1.0;
  const uint32_t i = positions[g];
  const size_t texel = size_t(vp.y) * c.layout.resolution + vp.x;
  return compressed_lit(c, i, texel, vp.q) ? 1.0 : 0.0;
}

double visibility_filtered(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p,
                           const Vec3& d) {
  const StackLayout& l = c.layout;
  const ViewCell v = view_cell(l, d);
  auto view = [&](int j, int k) { return texels_bilinear(c, positions, uint32_t(j * l.views_phi + k), p); };
  return lerp(lerp(view(v.j0, v.k0), view(v.j0, v.k1), v.fx), lerp(view(v.j1, v.k0), view(v.j1, v.k1), v.fx), v.fy);
}

double visibility_roulette(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p,
                           const Vec3& d, const std::array<float, 4>& r) {
  const StackLayout& l = c.layout;
  const ViewCell v = view_cell(l, d);
  const uint32_t g = uint32_t((r[0] < v.fy ? v.j1 : v.j0) * l.views_phi + (r[1] < v.fx ? v.k1 : v.k0));
  const TexelCell t = texel_cell(l, g, p);
  return texel_lit(c, positions, g, t.x + (r[2] < t.fx ? 1 : 0), t.y + (r[3] < t.fy ? 1 : 0), t.q) ? 1.0 : 0.0;
}

double local_visibility(const CompressedStack& c, const LocalLight& light, const std::vector<uint32_t>& positions,
                        uint32_t grid, const Vec3& p) {
  const CubePoint cp = cube_project(light, c.layout.resolution, light.sample_point(grid), p);
  const uint32_t map = uint32_t(cp.face) * uint32_t(light.count()) + positions[grid];
  return compressed_lit(c, map, size_t(cp.y) * c.layout.resolution + size_t(cp.x), cp.q) ? 1.0 : 0.0;
}

}  // namespace sf::ref::coherent

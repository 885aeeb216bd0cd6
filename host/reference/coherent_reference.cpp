#include "shadowfilter/vec3.hpp"
#include "coherent_reference.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sf::ref::coherent {

using namespace sf::coherent;

namespace {
// z2 with kNoSurface read as +infinity.
uint32_t upper(uint16_t z2) { return z2 == kNoSurface ? 65536u : z2; }

constexpr double kPi = 3.14159265358979323846;

double lerp(double a, double b, double f) { return a + f * (b - a); }

// Bilinear PCF of the 2x2 texels nearest to p in view g: project()'s geometry without the floor
// (continuous u M, v M, the same clamp to [-1, 2] and the same quantised depth).
double texels_bilinear(const CompressedStack& c, const std::vector<uint32_t>& positions, uint32_t g, const Vec3& p) {
  const StackLayout& l = c.layout;
  const ViewFrame f = view_frame(l, g);
  const Vec3 r{p[0] - l.center[0], p[1] - l.center[1], p[2] - l.center[2]};
  auto dot = [&](const Vec3& a) { return r[0] * a[0] + r[1] * a[1] + r[2] * a[2]; };
  const double scale = 1.0 / (2.0 * l.radius);
  const double u = std::clamp(dot(f.right) * scale + 0.5, -1.0, 2.0) * l.resolution - 0.5;
  const double v = std::clamp(dot(f.up) * scale + 0.5, -1.0, 2.0) * l.resolution - 0.5;
  const uint32_t q =
      uint32_t(std::clamp(std::nearbyint((l.radius - dot(f.dir)) * scale * kDepthMax), 0.0, double(kDepthMax)));
  const double x0 = std::floor(u), y0 = std::floor(v);
  const int x = int(x0), y = int(y0);
  auto lit = [&](int tx, int ty) {
    if (tx < 0 || ty < 0 || tx >= l.resolution || ty >= l.resolution) return 1.0;
    return compressed_lit(c, positions[g], size_t(ty) * l.resolution + tx, q) ? 1.0 : 0.0;
  };
  return lerp(lerp(lit(x, y), lit(x + 1, y), u - x0), lerp(lit(x, y + 1), lit(x + 1, y + 1), u - x0), v - y0);
}
}  // namespace

CompressedStack compress(const DualDepthStack& s) {
  validate(s.layout);
  const size_t texels = s.layout.texels();
  const uint32_t n = uint32_t(s.layout.views());
  // Every texel's run is grown map by map in sequence order (the stack is read once, in memory
  // order): a map that leaves no separating depth closes the run before it and starts the next.
  std::vector<uint32_t> lo(texels), hi(texels);
  std::vector<std::vector<uint32_t>> runs(texels);
  for (size_t t = 0; t < texels; ++t) {
    lo[t] = s.z1[t];
    hi[t] = upper(s.z2[t]);
  }
  for (uint32_t i = 1; i < n; ++i) {
    const uint16_t* z1 = s.z1.data() + size_t(i) * texels;
    const uint16_t* z2 = s.z2.data() + size_t(i) * texels;
    for (size_t t = 0; t < texels; ++t) {
      const uint32_t l2 = std::max(lo[t], uint32_t(z1[t])), h2 = std::min(hi[t], upper(z2[t]));
      if (l2 < h2) {
        lo[t] = l2;
        hi[t] = h2;
        continue;
      }
      runs[t].push_back((((lo[t] + hi[t]) / 2) << kSegmentDepthShift) | (i - 1));
      lo[t] = z1[t];
      hi[t] = upper(z2[t]);
    }
  }
  CompressedStack c;
  c.layout = s.layout;
  c.offsets.assign(texels + 1, 0);
  size_t total = texels;
  for (const auto& r : runs) total += r.size();
  c.segments.reserve(total);
  for (size_t t = 0; t < texels; ++t) {
    c.offsets[t] = uint32_t(c.segments.size());
    c.segments.insert(c.segments.end(), runs[t].begin(), runs[t].end());
    c.segments.push_back((((lo[t] + hi[t]) / 2) << kSegmentDepthShift) | (n - 1));
  }
  c.offsets[texels] = uint32_t(c.segments.size());
  return c;
}

uint16_t segment_depth(const CompressedStack& c, size_t texel, uint32_t i) {
  uint32_t lo = c.offsets[texel], hi = c.offsets[texel + 1] - 1;  // the answer is in [lo, hi]
  while (lo < hi) {
    const uint32_t mid = (lo + hi) / 2;
    if ((c.segments[mid] & kSegmentIndexMask) < i)
      lo = mid + 1;
    else
      hi = mid;
  }
  return uint16_t(c.segments[lo] >> kSegmentDepthShift);
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
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double t = std::acos(std::clamp(d[1] / n, -1.0, 1.0));
  double ph = std::atan2(d[2], d[0]);
  if (ph < 0.0) ph += 2.0 * kPi;
  const double rows = std::clamp(t / kPi * l.views_theta - 0.5, 0.0, double(l.views_theta - 1));
  const double cols = ph / (2.0 * kPi) * l.views_phi - 0.5;
  const int j0 = std::min(int(rows), l.views_theta - 1), j1 = std::min(j0 + 1, l.views_theta - 1);
  const double c0 = std::floor(cols);
  const int k0 = (int(c0) + l.views_phi) % l.views_phi, k1 = (k0 + 1) % l.views_phi;
  const double fy = rows - j0, fx = cols - c0;
  auto view = [&](int j, int k) { return texels_bilinear(c, positions, uint32_t(j * l.views_phi + k), p); };
  return lerp(lerp(view(j0, k0), view(j0, k1), fx), lerp(view(j1, k0), view(j1, k1), fx), fy);
}

}  // namespace sf::ref::coherent

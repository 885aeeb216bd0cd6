#include "coherent_reference.hpp"

#include <algorithm>

namespace sf::ref::coherent {

using namespace sf::coherent;

namespace {
// z2 with kNoSurface read as +infinity.
uint32_t upper(uint16_t z2) { return z2 == kNoSurface ? 65536u : z2; }
}  // namespace

CompressedStack compress(const DualDepthStack& s) {
  validate(s.layout);
  const size_t texels = s.layout.texels();
  const uint32_t n = uint32_t(s.layout.views());
  CompressedStack c;
  c.layout = s.layout;
  c.offsets.assign(texels + 1, 0);
  for (size_t t = 0; t < texels; ++t) {
    c.offsets[t] = uint32_t(c.segments.size());
    uint32_t i = 0;
    while (i < n) {
      uint32_t lo = s.z1[size_t(i) * texels + t], hi = upper(s.z2[size_t(i) * texels + t]);
      uint32_t end = i;
      while (end + 1 < n) {
        const uint32_t l2 = std::max(lo, uint32_t(s.z1[size_t(end + 1) * texels + t]));
        const uint32_t h2 = std::min(hi, upper(s.z2[size_t(end + 1) * texels + t]));
        if (l2 >= h2) break;
        lo = l2;
        hi = h2;
        ++end;
      }
      const uint32_t z_avg = (lo + hi) / 2;
      c.segments.push_back((z_avg << kSegmentDepthShift) | end);
      i = end + 1;
    }
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

double visibility(const CompressedStack& c, const std::vector<uint32_t>& positions, const std::array<double, 3>& p,
                  const std::array<double, 3>& d) {
  const uint32_t g = view_of_direction(c.layout, d);
  const ViewPoint vp = project(c.layout, g, p);
  if (!vp.inside(c.layout.resolution)) return 1.0;
  const uint32_t i = positions[g];
  const size_t texel = size_t(vp.y) * c.layout.resolution + vp.x;
  return compressed_lit(c, i, texel, vp.q) ? 1.0 : 0.0;
}

}  // namespace sf::ref::coherent

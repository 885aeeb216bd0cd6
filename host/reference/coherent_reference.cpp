#include "coherent_reference.hpp"

#include <algorithm>
#include <vector>

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

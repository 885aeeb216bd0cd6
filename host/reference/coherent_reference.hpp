#pragma once
// Scalar reference of coherent shadow maps (methods.md sec. 5; Ritschel 2007 sec. 3): the greedy
// segment fit, the segment lookup and the visibility tests, plain loops the device kernels are
// compared against byte for byte.
#include <array>
#include <cstdint>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "shadowfilter/coherent.hpp"

namespace sf::ref::coherent {

using sf::coherent::CompressedStack;
using sf::coherent::DualDepthStack;

// Ritschel 2007 eq. (1), per texel: from the first map not yet covered, the longest run of maps whose
// max z1 < min z2 (z2 = kNoSurface counts as +infinity, 65536), stored with
// z_avg = floor((max z1 + min z2) / 2), so max z1 <= z_avg < min z2 over the run.
CompressedStack compress(const DualDepthStack& stack);

// The same fit fed in sequence order a few maps at a time (a chunk a build renders, a part a merge
// reads): its memory is the per-texel state and the segments so far, not the stack. Feeding every
// map, in any chunks, then finish() gives compress()'s segments, byte for byte (compress() is
// this with one chunk).
class StreamingFit {
 public:
  explicit StreamingFit(const sf::coherent::StackLayout& layout);
  // Maps next() .. next() + count - 1, z1 and z2 as DualDepthStack holds them (map after map).
  void add(const uint16_t* z1, const uint16_t* z2, uint32_t count);
  uint32_t next() const { return next_; }
  // The compressed stack; InputError when not every view was added.
  CompressedStack finish();

 private:
  sf::coherent::StackLayout layout_;
  uint32_t next_ = 0;
  std::vector<uint32_t> lo_, hi_;
  std::vector<std::vector<uint64_t>> runs_;  // (z_avg << 32) | i_last of each closed run
};

// z_avg of the segment of texel t that holds map i (binary search over i_last).
uint16_t segment_depth(const CompressedStack& c, size_t texel, uint32_t i);

// The uncompressed dual-depth test of depth q in map i at texel t: +1 lit (q <= z1), 0 blocked
// (q >= z2), -1 between the two surfaces (inside the object: either answer is right there).
int stack_test(const DualDepthStack& s, uint32_t i, size_t texel, uint32_t q);
// The compressed test: lit when q <= z_avg. Lossless: equals stack_test wherever that is not -1.
bool compressed_lit(const CompressedStack& c, uint32_t i, size_t texel, uint32_t q);

// Visibility of point p toward direction d (any length): the view whose cell holds d, p's texel
// and depth there, the compressed test; 1 outside the map. (Ritschel 2007 sec. 3.2, fig. 6)
// positions: sf::coherent::sequence_positions(c.layout), computed once by the caller.
double visibility(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p, const Vec3& d);

// Generalized PCF (Ritschel 2007 sec. 4.5), the twin of coherent/query.clh's sf_coherent_visibility_filtered:
// the 2x2 views nearest to d in continuous lat-long coordinates (row t / pi T - 1/2 clamped to
// [0, T - 1], column p / (2 pi) P - 1/2 wrapping around), in each the 2x2 texels nearest to p
// (x = u M - 1/2; outside the map lit) tested at p's depth in that view, weighted bilinearly:
// lerp(lerp(.., fx), lerp(.., fx), fy) at both levels, so that 16 equal tests give exactly that
// value.
double visibility_filtered(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p,
                           const Vec3& d);

// Russian-roulette filtering (Ritschel 2007 sec. 4.5): one of generalized PCF's 16 (view, texel)
// pairs, drawn with its bilinear weight as probability from four uniform numbers r in [0, 1):
// row j1 when r[0] < fy, column k1 when r[1] < fx, then texel column x + 1 when r[2] < the texel
// fraction in x, row y + 1 when r[3] < that in y. One binary test (0 or 1) whose expectation over r
// is visibility_filtered(): PCF's answer at nearest's cost. Twin of sf_coherent_visibility_roulette.
double visibility_roulette(const CompressedStack& c, const std::vector<uint32_t>& positions, const Vec3& p,
                           const Vec3& d, const std::array<float, 4>& r);

// Visibility of point p from sampling point `grid` of a local light (Ritschel 2007 sec. 3.3 and
// 4.2): the cube face, texel and planar depth of p - s (cube_project), the compressed test in map
// face N + positions[grid] of the light's stack (c.layout: cube_layout). 1 lit, 0 blocked.
double local_visibility(const CompressedStack& c, const sf::coherent::LocalLight& light,
                        const std::vector<uint32_t>& positions, uint32_t grid, const Vec3& p);

}  // namespace sf::ref::coherent

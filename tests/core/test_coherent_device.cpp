// Coherent shadow maps on the device (host/include/shadowfilter/coherent_device.hpp) against
// the scalar reference (host/reference/coherent_reference.hpp): the compression byte for byte,
// the compressed query against the uncompressed one (lossless), the float query against the
// double one, the generalized PCF against its double twin, and the refusals of bad input.
// Stacks are small (16x16 views, M = 32) and synthetic: analytic spheres and a thin disc ray
// cast in double (a consistent scene), smooth random depth functions with thin surfaces, misses
// and open backs, and white noise (the worst case: a segment every map or two).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "coherent_reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::test {
namespace {

using namespace sf::coherent;
constexpr double kPi = 3.14159265358979323846;

Vec3 add(const Vec3& a, const Vec3& b, double s = 1.0) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }

StackLayout layout_of(int theta, int phi, int m, Ordering o, FarPlane far = FarPlane::Sphere) {
  StackLayout l;
  l.views_theta = theta;
  l.views_phi = phi;
  l.resolution = m;
  l.ordering = o;
  l.far_plane = far;
  l.center = {0.3, -0.2, 0.1};  // off the origin, radius not 1: the kernels' transform is tested
  l.radius = 1.5;
  return l;
}

// Two spheres and a thin disc inside the bounding sphere, ray cast in double from every texel
// centre of every view: z1 the first hit, z2 the second (far: the bounding sphere's exit or
// +infinity), the disc a surface pair thinner than a step (z2 = z1 + 1), misses 65535 / 65535.
DualDepthStack sphere_scene(const StackLayout& l) {
  DualDepthStack s;
  s.layout = l;
  const size_t texels = l.texels();
  s.z1.assign(size_t(l.views()) * texels, kNoSurface);
  s.z2 = s.z1;
  const std::vector<uint32_t> pos = sequence_positions(l);
  const double R = l.radius;
  struct Ball {
    Vec3 c;
    double r;
  };
  const Ball balls[] = {{add(l.center, {0.2 * R, 0.1 * R, -0.1 * R}), 0.35 * R},
                        {add(l.center, {-0.35 * R, -0.2 * R, 0.25 * R}), 0.25 * R}};
  const Vec3 disc_c = add(l.center, {0.1 * R, -0.5 * R, -0.3 * R});
  const Vec3 disc_n{0.3, 0.9, 0.3};
  const double disc_r = 0.35 * R, nn = std::sqrt(dot(disc_n, disc_n));
  for (int g = 0; g < l.views(); ++g) {
    const ViewFrame f = view_frame(l, uint32_t(g));
    for (int y = 0; y < l.resolution; ++y)
      for (int x = 0; x < l.resolution; ++x) {
        const double a = ((x + 0.5) / l.resolution - 0.5) * 2.0 * R, b = ((y + 0.5) / l.resolution - 0.5) * 2.0 * R;
        const Vec3 o = add(add(add(l.center, f.dir, R), f.right, a), f.up, b);  // on the camera plane
        const Vec3 dir{-f.dir[0], -f.dir[1], -f.dir[2]};
        std::vector<double> hits;  // ray parameter (distance from the plane)
        for (const Ball& ball : balls) {
          const Vec3 oc = add(o, ball.c, -1.0);
          const double bb = dot(oc, dir), cc = dot(oc, oc) - ball.r * ball.r, disc = bb * bb - cc;
          if (disc <= 0) continue;
          hits.push_back(-bb - std::sqrt(disc));
          hits.push_back(-bb + std::sqrt(disc));
        }
        const double den = dot(dir, disc_n) / nn;
        if (std::abs(den) > 1e-9) {
          const double s_hit = dot(add(disc_c, o, -1.0), disc_n) / nn / den;
          const Vec3 h = add(o, dir, s_hit);
          if (dot(add(h, disc_c, -1.0), add(h, disc_c, -1.0)) < disc_r * disc_r) hits.insert(hits.end(), 2, s_hit);
        }
        if (hits.empty()) continue;  // a miss: 65535 / 65535
        std::sort(hits.begin(), hits.end());
        const size_t second = l.depth_pair == DepthPair::FirstThird ? 2 : 1;
        const double rho2 = a * a + b * b;
        const double far = l.far_plane == FarPlane::Infinite ? -1.0 : R + std::sqrt(std::max(R * R - rho2, 0.0));
        const auto quantise = [&](double s_ray) {
          return std::clamp(std::nearbyint(s_ray / (2.0 * R) * kDepthMax), 0.0, double(kDepthMax));
        };
        const double z1 = std::min(quantise(hits[0]), double(kDepthMax - 1));
        double z2 = hits.size() > second ? quantise(hits[second]) : (far < 0 ? double(kNoSurface) : quantise(far));
        if (z2 != kNoSurface) z2 = std::max(z2, z1 + 1.0);
        const size_t at = size_t(pos[g]) * texels + size_t(y) * l.resolution + x;
        s.z1[at] = uint16_t(z1);
        s.z2[at] = uint16_t(z2);
      }
  }
  return s;
}

// Smooth random depth functions of the view's grid cell and the texel, per texel one of: a
// thin surface (z2 = z1 + 1), an open back (z2 = 65535), a thick one; misses where the function
// passes a threshold (so texels switch between hit and miss along the sequence).
DualDepthStack smooth_random(const StackLayout& l, unsigned seed) {
  DualDepthStack s;
  s.layout = l;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double w[6] = {u(rng) * 0.6, u(rng) * 0.6, u(rng) * 0.3, u(rng) * 0.3, u(rng) * 6.0, u(rng) * 6.0};
  const size_t texels = l.texels();
  std::vector<int> kind(texels);
  for (int& k : kind) k = int(u(rng) * 4);
  s.z1.resize(size_t(l.views()) * texels);
  s.z2.resize(s.z1.size());
  const std::vector<uint32_t> pos = sequence_positions(l);
  for (int g = 0; g < l.views(); ++g) {
    const int j = g / l.views_phi, k = g % l.views_phi;
    for (size_t t = 0; t < texels; ++t) {
      const int x = int(t % l.resolution), y = int(t / l.resolution);
      const double f = std::sin(w[0] * j + w[2] * x + w[4]) * std::cos(w[1] * k + w[3] * y + w[5]);
      const size_t at = size_t(pos[g]) * texels + t;
      if (f > 0.8) {
        s.z1[at] = s.z2[at] = kNoSurface;
        continue;
      }
      const uint16_t z1 = uint16_t(30000 + 25000 * f + 3000 * std::sin(0.7 * x + 0.3 * j));
      s.z1[at] = z1;
      s.z2[at] = kind[t] == 0   ? uint16_t(z1 + 1)
                 : kind[t] == 1 ? kNoSurface
                                : uint16_t(z1 + 2 + int(4000 * (1.0 + std::cos(0.2 * k + 0.5 * y))));
    }
  }
  return s;
}

// White noise: no coherence at all, a segment every map or two (the compression's worst case),
// with z1 = 0, z2 = 65534 and open backs among the values.
DualDepthStack noise_stack(const StackLayout& l, unsigned seed) {
  DualDepthStack s;
  s.layout = l;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> z(0, kDepthMax - 1), gap(1, 200), kind(0, 9);
  s.z1.resize(size_t(l.views()) * l.texels());
  s.z2.resize(s.z1.size());
  for (size_t i = 0; i < s.z1.size(); ++i) {
    const int k = kind(rng);
    const int z1 = k == 0 ? 0 : z(rng);
    s.z1[i] = uint16_t(k == 1 ? kNoSurface : z1);
    s.z2[i] = uint16_t(k == 1 || k == 2 ? kNoSurface : std::min(z1 + gap(rng), int(kDepthMax)));
  }
  return s;
}

// Queries: points uniform in the ball of `fraction` times the bounding radius, directions
// uniform on the sphere (xyz, w = 0), as float4.
struct Queries {
  std::vector<float> points, dirs;  // 4 floats each
  size_t count = 0;
  Vec3 point(size_t i) const { return {points[4 * i], points[4 * i + 1], points[4 * i + 2]}; }
  Vec3 dir(size_t i) const { return {dirs[4 * i], dirs[4 * i + 1], dirs[4 * i + 2]}; }
};

Queries random_queries(const StackLayout& l, size_t count, unsigned seed, double fraction = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  Queries q;
  q.count = count;
  q.points.resize(4 * count);
  q.dirs.resize(4 * count);
  for (size_t i = 0; i < count; ++i) {
    Vec3 p;
    do p = {u(rng), u(rng), u(rng)};
    while (dot(p, p) > 1.0);
    Vec3 d;
    do d = {n(rng), n(rng), n(rng)};
    while (dot(d, d) < 1e-6);
    for (int c = 0; c < 3; ++c) {
      q.points[4 * i + c] = float(l.center[c] + fraction * l.radius * p[c]);
      q.dirs[4 * i + c] = float(d[c] / std::sqrt(dot(d, d)));
    }
  }
  return q;
}

struct DeviceQueries {
  cl::Buffer points, dirs, out;
};
DeviceQueries to_device(const Queries& q) {
  return {test::to_device(q.points), test::to_device(q.dirs), test::to_device(std::vector<float>(q.count, -7.0f))};
}

std::vector<float> visibility(const DeviceStack& s, const DeviceQueries& d, size_t count, CoherentFilter filter,
                              CoherentToward toward = CoherentToward::Direction) {
  enqueue_visibility(runtime(), filter, toward, count, s, d.points, d.dirs, d.out).wait();
  return from_device(d.out, count);
}
std::vector<float> visibility(const DeviceStack& s, const Queries& q, CoherentFilter filter,
                              CoherentToward toward = CoherentToward::Direction) {
  return visibility(s, to_device(q), q.count, filter, toward);
}

std::vector<float> stack_test(const DeviceDualDepth& s, const DeviceQueries& d, size_t count) {
  enqueue_stack_test(runtime(), CoherentToward::Direction, count, s, d.points, d.dirs, d.out).wait();
  return from_device(d.out, count);
}
std::vector<float> stack_test(const DeviceDualDepth& s, const Queries& q) {
  return stack_test(s, to_device(q), q.count);
}

// The query's double-precision coordinates lie within `eps` of a boundary the float query may
// fall on the other side of: a grid cell edge (view), a texel edge, or the depth step's
// rounding edge next to the texel's z_avg (q <= z_avg flips between z_avg and z_avg + 1).
bool near_boundary(const CompressedStack& c, const std::vector<uint32_t>& pos, const Vec3& p, const Vec3& d,
                   double eps_cell, double eps_depth) {
  const StackLayout& l = c.layout;
  const auto edge = [](double x, double eps) { return std::abs(x - std::nearbyint(x)) < eps; };
  const double t = std::acos(std::clamp(d[1] / std::sqrt(dot(d, d)), -1.0, 1.0));
  double ph = std::atan2(d[2], d[0]);
  if (ph < 0) ph += 2 * kPi;
  if (edge(t / kPi * l.views_theta, eps_cell) || edge(ph / (2 * kPi) * l.views_phi, eps_cell)) return true;
  const uint32_t g = view_of_direction(l, d);
  const ViewFrame f = view_frame(l, g);
  const Vec3 r = add(p, l.center, -1.0);
  const double scale = 1.0 / (2.0 * l.radius);
  const double u = (dot(r, f.right) * scale + 0.5) * l.resolution, v = (dot(r, f.up) * scale + 0.5) * l.resolution;
  if (edge(u, eps_cell) || edge(v, eps_cell)) return true;
  const ViewPoint vp = project(l, g, p);
  if (!vp.inside(l.resolution)) return false;
  const double z = ref::coherent::segment_depth(c, size_t(vp.y) * l.resolution + vp.x, pos[g]);
  return std::abs((l.radius - dot(r, f.dir)) * scale * kDepthMax - (z + 0.5)) < eps_depth;
}

double segments_per_texel(const CompressedStack& c) { return double(c.segment_count()) / c.layout.texels(); }

// --- (1) compression ---------------------------------------------------------------------------

// The device's offsets and segments equal the reference's word for word (exact: both run the
// same integer greedy walk). Layouts: every ordering, odd grids and map sides (texel counts
// that fill no work-group), one view, one texel, more views than 16 bits index, both far planes
// and depth pairs' test stacks.
TEST(CoherentDevice, CompressionEqualsTheReferenceByteForByte) {
  struct Case {
    StackLayout layout;
    int generator;  // 0 spheres, 1 smooth random, 2 noise
  };
  std::vector<Case> cases;
  for (Ordering o : {Ordering::ScanLine, Ordering::ZigZag, Ordering::Hilbert})
    for (int gen : {0, 1, 2}) cases.push_back({layout_of(16, 16, 32, o), gen});
  cases.push_back({layout_of(16, 16, 32, Ordering::Hilbert, FarPlane::Infinite), 0});
  StackLayout third = layout_of(8, 8, 24, Ordering::Hilbert);
  third.depth_pair = DepthPair::FirstThird;
  cases.push_back({third, 0});
  cases.push_back({layout_of(3, 5, 7, Ordering::ZigZag), 1});
  cases.push_back({layout_of(5, 3, 13, Ordering::ScanLine), 2});
  cases.push_back({layout_of(1, 1, 9, Ordering::ScanLine), 1});
  cases.push_back({layout_of(4, 4, 1, Ordering::Hilbert), 2});
  cases.push_back({layout_of(2, 7, 67, Ordering::ZigZag), 0});       // 4489 texels: > one scan block, partial
  cases.push_back({layout_of(300, 300, 2, Ordering::ScanLine), 2});  // 90,000 views: indices past 16 bits
  for (size_t n = 0; n < cases.size(); ++n) {
    const Case& k = cases[n];
    const DualDepthStack s = k.generator == 0   ? sphere_scene(k.layout)
                             : k.generator == 1 ? smooth_random(k.layout, unsigned(n))
                                                : noise_stack(k.layout, unsigned(n));
    const CompressedStack want = ref::coherent::compress(s);
    const CompressedStack got = compress_on_device(runtime(), s);
    const std::string what = "case " + std::to_string(n) + " (" + ordering_name(k.layout.ordering) + ", " +
                             std::to_string(k.layout.views_theta) + "x" + std::to_string(k.layout.views_phi) +
                             " views, M " + std::to_string(k.layout.resolution) + ", generator " +
                             std::to_string(k.generator) + ", " + std::to_string(segments_per_texel(want)) +
                             " segments per texel)";
    ASSERT_EQ(got.offsets.size(), want.offsets.size()) << what;
    ASSERT_EQ(got.segment_count(), want.segment_count()) << what;
    EXPECT_TRUE(got.offsets == want.offsets) << what;
    EXPECT_TRUE(got.last == want.last) << what;
    EXPECT_TRUE(got.depth == want.depth) << what;
  }
}

// The enqueue-level passes on caller buffers: last and depth buffers one segment short of the
// total keep every segment that fits and write nothing past their capacity (the entry after it,
// in larger buffers, keeps its sentinel).
TEST(CoherentDevice, CompressionPassesOnCallerBuffersRespectCapacity) {
  const StackLayout l = layout_of(4, 4, 9, Ordering::Hilbert);
  const DualDepthStack s = smooth_random(l, 3);
  const CompressedStack want = ref::coherent::compress(s);
  Runtime& rt = runtime();
  const DeviceDualDepth z = upload(rt, s);
  cl::Buffer offsets(rt.context(), CL_MEM_READ_WRITE, (l.texels() + 1) * 4);
  cl::Buffer scratch(rt.context(), CL_MEM_READ_WRITE, compress_scratch_bytes(l));
  const EventList counted{enqueue_compress_count(rt, l, z.z1, z.z2, offsets)};
  const EventList scanned{enqueue_compress_scan(rt, l, offsets, scratch, nullptr, &counted)};
  uint64_t total = 0;
  rt.queue().enqueueReadBuffer(scratch, CL_TRUE, compress_total_offset(l), 8, &total, &scanned);
  ASSERT_EQ(total, want.segment_count());
  const size_t capacity = want.segment_count() - 1;
  std::vector<uint32_t> last(want.segment_count() + 1, 0xdeadbeefu);
  std::vector<uint16_t> depth(want.segment_count() + 1, 0xbeefu);
  cl::Buffer last_buffer(rt.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, last.size() * 4, last.data());
  cl::Buffer depth_buffer(rt.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, depth.size() * 2, depth.data());
  enqueue_compress_write(rt, l, capacity, z.z1, z.z2, offsets, last_buffer, depth_buffer, &scanned).wait();
  rt.queue().enqueueReadBuffer(last_buffer, CL_TRUE, 0, last.size() * 4, last.data());
  rt.queue().enqueueReadBuffer(depth_buffer, CL_TRUE, 0, depth.size() * 2, depth.data());
  for (size_t i = 0; i < capacity; ++i) {
    ASSERT_EQ(last[i], want.last[i]) << "segment " << i;
    ASSERT_EQ(depth[i], want.depth[i]) << "segment " << i;
  }
  EXPECT_EQ(last[capacity], 0xdeadbeefu);
  EXPECT_EQ(last[capacity + 1], 0xdeadbeefu);
  EXPECT_EQ(depth[capacity], 0xbeefu);
}

// --- (2) lossless ------------------------------------------------------------------------------

// 10^6 random points in the bounding sphere toward random directions: the compressed query
// equals the uncompressed dual-depth test exactly wherever that is not -1 (between the two
// surfaces, where either answer is right), for every ordering. Both run the same float
// projection, so they test the same view, texel and depth q: the compression alone differs.
// The uncompressed answer depends on the view, not on where the ordering stores its map, so one
// run of it (scan-line) is the truth of all three.
TEST(CoherentDevice, CompressedQueryIsLosslessForEveryOrdering) {
  constexpr size_t kQueries = 1000000;
  const DeviceQueries q = to_device(random_queries(layout_of(16, 16, 32, Ordering::ScanLine), kQueries, 11));
  const std::vector<float> truth =
      stack_test(upload(runtime(), sphere_scene(layout_of(16, 16, 32, Ordering::ScanLine))), q, kQueries);
  size_t between = 0, lit = 0, blocked = 0;
  for (float t : truth) (t == -1.0f ? between : t == 1.0f ? lit : blocked)++;
  RecordProperty("between_surfaces", std::to_string(between));
  std::printf("[ lossless ] %zu of %zu queries between the surfaces (-1), %zu lit, %zu blocked\n", between, kQueries,
              lit, blocked);
  // The scene is not trivial: each answer is common.
  EXPECT_GT(blocked, kQueries / 20);
  EXPECT_GT(lit, kQueries / 2);
  EXPECT_GT(between, kQueries / 100);
  for (Ordering o : {Ordering::ScanLine, Ordering::ZigZag, Ordering::Hilbert}) {
    const StackLayout l = layout_of(16, 16, 32, o);
    const DeviceStack c = compress_on_device(runtime(), upload(runtime(), sphere_scene(l)));
    const std::vector<float> got = visibility(c, q, kQueries, CoherentFilter::Nearest);
    size_t wrong = 0, binary = 0;
    for (size_t i = 0; i < kQueries; ++i) {
      binary += got[i] == 0.0f || got[i] == 1.0f;
      wrong += truth[i] != -1.0f && got[i] != truth[i];
    }
    std::printf("[ lossless ] %s: %zu wrong, %.2f segments per texel\n", ordering_name(o), wrong,
                double(c.segment_count) / l.texels());
    EXPECT_EQ(wrong, 0u) << ordering_name(o);
    EXPECT_EQ(binary, kQueries) << ordering_name(o);
  }
}

// Same on the smooth random stack (thin surfaces, open backs, misses switching along the
// sequence): 2 10^5 queries, zero differences.
TEST(CoherentDevice, CompressedQueryIsLosslessOnThinAndOpenSurfaces) {
  const StackLayout l = layout_of(16, 16, 32, Ordering::Hilbert);
  const DualDepthStack s = smooth_random(l, 5);
  const DeviceStack c = compress_on_device(runtime(), upload(runtime(), s));
  const Queries q = random_queries(l, 200000, 21);
  const std::vector<float> got = visibility(c, q, CoherentFilter::Nearest);
  const std::vector<float> truth = stack_test(upload(runtime(), s), q);
  size_t wrong = 0, between = 0;
  for (size_t i = 0; i < q.count; ++i) {
    if (truth[i] == -1.0f)
      ++between;
    else if (got[i] != truth[i])
      ++wrong;
  }
  RecordProperty("between_surfaces", std::to_string(between));
  EXPECT_EQ(wrong, 0u) << between << " of " << q.count << " between the surfaces";
}

// --- (3) nearest query against the double reference -----------------------------------------

// The float query agrees with sf::ref::coherent::visibility (double) on all but a fraction
// < 1e-3 of 10^6 queries, and every disagreement is explained: its double coordinates lie
// within 1e-3 cells / texels of a view or texel edge, or within 0.1 depth steps of the rounding
// edge next to the texel's z_avg. Float's rounding of the angles and of the projections (about
// 1e-6 relative) moves a query across such an edge and nowhere else.
TEST(CoherentDevice, NearestQueryAgreesWithTheDoubleReference) {
  constexpr size_t kQueries = 1000000;
  const StackLayout l = layout_of(16, 16, 32, Ordering::Hilbert);
  const CompressedStack c = ref::coherent::compress(sphere_scene(l));
  const std::vector<uint32_t> pos = sequence_positions(l);
  const Queries q = random_queries(l, kQueries, 31);
  const std::vector<float> got = visibility(upload(runtime(), c), q, CoherentFilter::Nearest);
  size_t differ = 0, unexplained = 0, lit = 0;
  for (size_t i = 0; i < kQueries; ++i) {
    const double want = ref::coherent::visibility(c, pos, q.point(i), q.dir(i));
    lit += want == 1.0;
    if (got[i] == float(want)) continue;
    ++differ;
    if (!near_boundary(c, pos, q.point(i), q.dir(i), 1e-3, 0.1)) ++unexplained;
  }
  RecordProperty("differ", std::to_string(differ));
  std::printf("[ nearest  ] %zu of %zu float queries differ from double (%zu lit)\n", differ, kQueries, lit);
  EXPECT_EQ(unexplained, 0u);
  EXPECT_LT(double(differ) / kQueries, 1e-3);
  EXPECT_GT(lit, kQueries / 2);
  EXPECT_LT(lit, kQueries - kQueries / 20);
}

// Semi-local lights: a light sample's position l gives direction l - p on the device, the same
// float subtraction as the host's: identical results to the direction queries, both filters.
TEST(CoherentDevice, LightPositionQueriesEqualDirectionQueries) {
  const StackLayout l = layout_of(16, 16, 32, Ordering::ZigZag);
  const DeviceStack c = upload(runtime(), ref::coherent::compress(sphere_scene(l)));
  Queries toward = random_queries(l, 100003, 41);  // not a multiple of any work-group size
  Queries dirs = toward;
  for (size_t i = 0; i < toward.count; ++i)
    for (int k = 0; k < 3; ++k) {
      toward.dirs[4 * i + k] = toward.points[4 * i + k] + 3.0f * toward.dirs[4 * i + k];  // l = p + 3 d
      dirs.dirs[4 * i + k] = toward.dirs[4 * i + k] - toward.points[4 * i + k];
    }
  for (CoherentFilter f : {CoherentFilter::Nearest, CoherentFilter::Pcf}) {
    const std::vector<float> a = visibility(c, toward, f, CoherentToward::Point), b = visibility(c, dirs, f);
    size_t differ = 0;
    for (size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
    EXPECT_EQ(differ, 0u) << "filter " << int(f);
  }
}

// --- (4) generalized PCF ----------------------------------------------------------------------

// Against sf::ref::coherent::visibility_filtered (double) on 2 10^5 queries: |device - double|
// <= 1e-4 on all but a fraction < 1e-3. Bilinear weights are continuous across view and texel
// edges, so float's rounding of the coordinates (about 1e-6 cells) moves the result by about
// that; a tap whose depth q rounds to the other side of its z_avg flips with its whole weight,
// which is the rare remainder.
TEST(CoherentDevice, FilteredQueryAgreesWithTheDoubleReference) {
  constexpr size_t kQueries = 200000;
  const StackLayout l = layout_of(16, 16, 32, Ordering::Hilbert);
  const CompressedStack c = ref::coherent::compress(sphere_scene(l));
  const std::vector<uint32_t> pos = sequence_positions(l);
  const Queries q = random_queries(l, kQueries, 51);
  const std::vector<float> got = visibility(upload(runtime(), c), q, CoherentFilter::Pcf);
  size_t off = 0, partial = 0, outside = 0;
  double worst_within = 0.0;
  for (size_t i = 0; i < kQueries; ++i) {
    const double want = ref::coherent::visibility_filtered(c, pos, q.point(i), q.dir(i));
    outside += !(got[i] >= 0.0f && got[i] <= 1.0f);
    partial += want > 0.0 && want < 1.0;
    const double e = std::abs(got[i] - want);
    if (e > 1e-4)
      ++off;
    else
      worst_within = std::max(worst_within, e);
  }
  std::printf("[ pcf      ] %zu of %zu differ by > 1e-4 from double, the rest by <= %.2e; %zu partly lit\n", off,
              kQueries, worst_within, partial);
  EXPECT_EQ(outside, 0u);
  EXPECT_LT(double(off) / kQueries, 1e-3);
  EXPECT_GT(partial, kQueries / 50);  // the filter does filter
}

// Constant visibility gives exactly 0 or 1: a stack of misses lights every query (1 exactly),
// a stack whose every texel holds a thin surface on the camera plane (z1 = 0, z2 = 1) blocks
// every point of depth >= 1 (0 exactly), for points within 0.8 of the radius, whose 2x2 texels
// all lie inside the map. NaN or zero directions give a value in [0, 1], never NaN.
TEST(CoherentDevice, FilteredQueryIsExactWhereVisibilityIsConstant) {
  const StackLayout l = layout_of(8, 8, 16, Ordering::Hilbert);
  DualDepthStack s;
  s.layout = l;
  s.z1.assign(size_t(l.views()) * l.texels(), kNoSurface);
  s.z2 = s.z1;
  Queries q = random_queries(l, 50000, 61, 0.8);
  const DeviceStack empty = compress_on_device(runtime(), upload(runtime(), s));
  EXPECT_EQ(empty.segment_count, l.texels());  // one segment per texel
  for (CoherentFilter f : {CoherentFilter::Nearest, CoherentFilter::Pcf}) {
    const std::vector<float> v = visibility(empty, q, f);
    EXPECT_EQ(std::count(v.begin(), v.end(), 1.0f), long(v.size())) << "filter " << int(f);
  }
  std::fill(s.z1.begin(), s.z1.end(), uint16_t(0));
  std::fill(s.z2.begin(), s.z2.end(), uint16_t(1));
  const DeviceStack wall = compress_on_device(runtime(), upload(runtime(), s));
  for (CoherentFilter f : {CoherentFilter::Nearest, CoherentFilter::Pcf}) {
    const std::vector<float> v = visibility(wall, q, f);
    EXPECT_EQ(std::count(v.begin(), v.end(), 0.0f), long(v.size())) << "filter " << int(f);
  }
  const float nan = std::nanf("");
  for (size_t i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) q.dirs[4 * i + k] = i == 0 ? 0.0f : i == 1 ? nan : (k == int(i) - 2 ? nan : 0.5f);
  q.points[4 * 3] = nan;
  for (CoherentFilter f : {CoherentFilter::Nearest, CoherentFilter::Pcf}) {
    const std::vector<float> v = visibility(wall, q, f);
    for (size_t i = 0; i < 4; ++i) EXPECT_TRUE(v[i] >= 0.0f && v[i] <= 1.0f) << "query " << i << ": " << v[i];
  }
}

// --- (5) refusals -------------------------------------------------------------------------------

template <typename F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(CoherentDevice, BadInputIsRefusedNamingTheField) {
  Runtime& rt = runtime();
  const StackLayout l = layout_of(4, 4, 8, Ordering::Hilbert);
  const DualDepthStack s = smooth_random(l, 7);
  const CompressedStack c = ref::coherent::compress(s);
  const DeviceStack d = upload(rt, c);
  const DeviceDualDepth z = upload(rt, s);
  const Queries q = random_queries(l, 100, 71);
  const DeviceQueries b = to_device(q);
  const cl::Buffer small(rt.context(), CL_MEM_READ_WRITE, 4);
  const auto has = [](const std::string& msg, const std::string& word) {
    return msg.find(word) != std::string::npos && msg.find('\n') == std::string::npos;
  };

  CompressedStack bad = c;
  bad.offsets.pop_back();
  EXPECT_TRUE(has(refusal([&] { upload(rt, bad); }), "offsets"));
  bad = c;
  bad.offsets[5] = bad.offsets[4];  // texel 4 without a segment
  EXPECT_TRUE(has(refusal([&] { upload(rt, bad); }), "offsets must increase"));
  bad = c;
  bad.last.pop_back();
  EXPECT_TRUE(has(refusal([&] { upload(rt, bad); }), "last and depth"));
  DualDepthStack bad_z = s;
  bad_z.z2.pop_back();
  EXPECT_TRUE(has(refusal([&] { upload(rt, bad_z); }), "z1 and z2"));
  bad_z = s;
  bad_z.layout.views_theta = 3;  // Hilbert on a 3x4 grid
  EXPECT_TRUE(has(refusal([&] { compress_on_device(rt, bad_z); }), "hilbert"));

  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, d, b.points,
                                       b.dirs, small);
                  }),
                  "out"));
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, d, cl::Buffer(),
                                       b.dirs, b.out);
                  }),
                  "points"));
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, d, b.points,
                                       small, b.out);
                  }),
                  "second"));
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, size_t(1) << 33, d,
                                       b.points, b.dirs, b.out);
                  }),
                  "count"));
  DeviceStack bad_d = d;
  bad_d.segment_count += 1;
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, bad_d, b.points,
                                       b.dirs, b.out);
                  }),
                  "last"));
  bad_d = d;
  bad_d.positions = small;
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, bad_d, b.points,
                                       b.dirs, b.out);
                  }),
                  "positions"));
  bad_d = d;
  bad_d.offsets = cl::Buffer();
  EXPECT_TRUE(has(refusal([&] {
                    enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, q.count, bad_d, b.points,
                                       b.dirs, b.out);
                  }),
                  "offsets"));
  EXPECT_TRUE(has(
      refusal([&] { enqueue_stack_test(rt, CoherentToward::Direction, q.count, z, b.points, b.dirs, small); }), "out"));
  DeviceDualDepth bad_dz = z;
  bad_dz.z1 = small;
  EXPECT_TRUE(
      has(refusal([&] { enqueue_stack_test(rt, CoherentToward::Direction, q.count, bad_dz, b.points, b.dirs, b.out); }),
          "z1"));
  EXPECT_TRUE(has(refusal([&] { compress_on_device(rt, bad_dz); }), "z1"));
  EXPECT_TRUE(has(refusal([&] { enqueue_compress_count(rt, l, z.z1, z.z2, small); }), "offsets"));
  EXPECT_TRUE(has(refusal([&] { enqueue_compress_scan(rt, l, d.offsets, small); }), "scratch"));
  EXPECT_TRUE(
      has(refusal([&] { enqueue_compress_write(rt, l, 0, z.z1, z.z2, d.offsets, d.last, d.depth); }), "capacity"));
  EXPECT_TRUE(
      has(refusal([&] { enqueue_compress_write(rt, l, c.segment_count(), z.z1, z.z2, d.offsets, small, d.depth); }),
          "last"));
  EXPECT_TRUE(
      has(refusal([&] { enqueue_compress_write(rt, l, c.segment_count(), z.z1, z.z2, d.offsets, d.last, small); }),
          "depth"));
  // count 0 is not an error: a marker after `wait`.
  enqueue_visibility(rt, CoherentFilter::Nearest, CoherentToward::Direction, 0, d, cl::Buffer(), cl::Buffer(),
                     cl::Buffer())
      .wait();
}

}  // namespace
}  // namespace sf::test

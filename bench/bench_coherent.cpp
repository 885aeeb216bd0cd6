// Coherent shadow maps (methods.md sec. 5, docs/coherent_device.md) on the device.
//   coherent/query_geometry_bound: the nearest query's geometry without the stack (a bound).
//   coherent/compress: the device compression of a 32x32-view, M = 128 stack (16.8 M texels of
//     z1 and z2, 64 MiB), count + scan + write; scan 0: the scan on the device (three small
//     launches), scan 1: the counts read back, scanned on the host and written again. bytes: z1
//     and z2 read twice (count and write) + counts, offsets and segments written.
//   coherent/query: 2^20 point queries, nearest (filter 0) or generalized PCF (filter 1); rx 0:
//     random points within 0.9 R toward random directions, rx 1: coherent, points of a grid in
//     scan order with one direction per 4096 of them (Fixture). bytes: what the kernel loads per query, counted on the
//     host by running the same lookups (query in 32, out 4, and per texel test: positions 4, offsets 8, 4 per index
//     the binary search reads and 2 for the depth found), cache hits included; Mtexel/s = M queries/s.
// The stack: Hilbert-ordered 32x32 views at M = 128 of the mesh SF_BENCH_COHERENT_MESH (e.g.
// build/meshes/bunny00.off, rendered with Embree as `coherent build` does; needs the scene
// library), else a synthetic one: 8 spheres and 2 thin discs ray cast in double. Its segments
// per texel are a counter of coherent/compress; the stack's name goes to stderr. Query points
// are given in units of the bounding sphere and placed in it. Smoke mode: 8x8 views at M = 32,
// 2^16 queries (the coherent grid 290 x 290), the same benchmarks.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "bench_common.hpp"
#ifdef SF_BENCH_HAVE_SCENE
#include "coherent_stack.hpp"
#endif
#include "coherent_reference.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::bench {
namespace {

using namespace sf::coherent;

Vec3 add(const Vec3& a, const Vec3& b, double s = 1.0) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }

// 32x32 views at M = 128 and 2^20 queries (smoke mode: a quarter of each side, 2^16 queries).
int views_side() { return smoke_scaled(32, 4); }
int resolution() { return smoke_scaled(128, 4); }
size_t query_count() { return size_t(smoke_scaled(1 << 20, 16)); }
std::string stack_name() {
  return std::to_string(views_side()) + "x" + std::to_string(views_side()) + "_M" + std::to_string(resolution());
}

// Random spheres (radii 0.17 .. 0.33 R, centres within 0.5 R) and two thin discs: first and
// second hit per texel of every view, far plane the bounding sphere's exit, misses 65535.
DualDepthStack synthetic_stack(int views_side, int m) {
  StackLayout l;
  l.views_theta = l.views_phi = views_side;
  l.resolution = m;
  l.ordering = Ordering::Hilbert;
  DualDepthStack s;
  s.layout = l;
  const size_t texels = l.texels();
  s.z1.assign(size_t(l.views()) * texels, kNoSurface);
  s.z2 = s.z1;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  struct Ball {
    Vec3 c;
    double r;
  };
  struct Disc {
    Vec3 c, n;
    double r;
  };
  std::vector<Ball> balls;
  std::vector<Disc> discs;
  const auto inside = [&](double within) {
    Vec3 p;
    do p = {u(rng), u(rng), u(rng)};
    while (dot(p, p) > 1.0);
    return Vec3{p[0] * within, p[1] * within, p[2] * within};
  };
  for (int i = 0; i < 8; ++i) balls.push_back({inside(0.5), 0.25 + 0.08 * u(rng)});
  for (int i = 0; i < 2; ++i) {
    Vec3 n = inside(1.0);
    const double len = std::sqrt(dot(n, n)) + 1e-9;
    discs.push_back({inside(0.6), {n[0] / len, n[1] / len, n[2] / len}, 0.2 + 0.05 * u(rng)});
  }
  const std::vector<uint32_t> pos = sequence_positions(l);
  std::vector<double> hits;
  for (int g = 0; g < l.views(); ++g) {
    const ViewFrame f = view_frame(l, uint32_t(g));
    const Vec3 dir{-f.dir[0], -f.dir[1], -f.dir[2]};
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x) {
        const double a = ((x + 0.5) / m - 0.5) * 2.0, b = ((y + 0.5) / m - 0.5) * 2.0;
        const Vec3 o = add(add(f.dir, f.right, a), f.up, b);  // radius 1, centre 0
        hits.clear();
        for (const Ball& ball : balls) {
          const Vec3 oc = add(o, ball.c, -1.0);
          const double bb = dot(oc, dir), disc = bb * bb - (dot(oc, oc) - ball.r * ball.r);
          if (disc <= 0) continue;
          hits.push_back(-bb - std::sqrt(disc));
          hits.push_back(-bb + std::sqrt(disc));
        }
        for (const Disc& d : discs) {
          const double den = dot(dir, d.n);
          if (std::abs(den) < 1e-9) continue;
          const double t = dot(add(d.c, o, -1.0), d.n) / den;
          const Vec3 h = add(add(o, dir, t), d.c, -1.0);
          if (dot(h, h) < d.r * d.r) hits.insert(hits.end(), 2, t);
        }
        if (hits.empty()) continue;
        std::sort(hits.begin(), hits.end());
        const auto q = [](double t) { return std::clamp(std::nearbyint(t / 2.0 * kDepthMax), 0.0, double(kDepthMax)); };
        const double z1 = std::min(q(hits[0]), double(kDepthMax - 1));
        const double far = 1.0 + std::sqrt(std::max(1.0 - a * a - b * b, 0.0));
        const double z2 = std::max(q(hits.size() > 1 ? hits[1] : far), z1 + 1.0);
        const size_t at = size_t(pos[g]) * texels + size_t(y) * m + x;
        s.z1[at] = uint16_t(z1);
        s.z2[at] = uint16_t(z2);
      }
  }
  return s;
}

// The mesh of SF_BENCH_COHERENT_MESH, or the synthetic stack.
DualDepthStack bench_stack() {
  const char* mesh = std::getenv("SF_BENCH_COHERENT_MESH");
  if (!mesh || !*mesh) {
    std::fprintf(stderr, "coherent stack: synthetic (8 spheres, 2 discs)\n");
    return synthetic_stack(views_side(), resolution());
  }
#ifdef SF_BENCH_HAVE_SCENE
  const scene::SceneGeometry object = scene::load_coherent_object(mesh);
  StackLayout l;  // Hilbert, depth pair 12, sphere far plane: the defaults
  l.views_theta = l.views_phi = views_side();
  l.resolution = resolution();
  scene::fit_bounding_sphere(object, l);
  std::fprintf(stderr, "coherent stack: %s\n", mesh);
  return scene::render_stack(object, l, 0);
#else
  throw InputError("SF_BENCH_COHERENT_MESH needs sf_bench built with the scene library (SF_BUILD_CLI)");
#endif
}

struct Fixture {
  DualDepthStack stack = bench_stack();
  DeviceDualDepth device = upload(runtime(), stack);
  DeviceStack compressed = compress_on_device(runtime(), device);
  CompressedStack host = download(runtime(), compressed);
  std::vector<uint32_t> positions = sequence_positions(stack.layout);
  std::vector<float> points, dirs;      // random
  std::vector<float> points_c, dirs_c;  // coherent
  const size_t queries = query_count();
  cl::Buffer d_points, d_dirs, d_points_c, d_dirs_c, d_out = device_buffer(queries * sizeof(float));
  Fixture() {
    const StackLayout& l = stack.layout;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::normal_distribution<double> n(0.0, 1.0);
    points.resize(4 * queries);
    dirs.resize(4 * queries);
    for (size_t i = 0; i < queries; ++i) {
      Vec3 p, d;
      do p = {u(rng), u(rng), u(rng)};
      while (dot(p, p) > 0.81);  // within 0.9 R: mostly around the objects
      do d = {n(rng), n(rng), n(rng)};
      while (dot(d, d) < 1e-6);
      const double len = std::sqrt(dot(d, d));
      for (int c = 0; c < 3; ++c)
        points[4 * i + c] = float(l.center[c] + l.radius * p[c]), dirs[4 * i + c] = float(d[c] / len);
    }
    d_points = to_device(points);
    d_dirs = to_device(dirs);
    // Coherent: points of a 1160 x 1160 grid on the slice y = 0 through the objects, in scan
    // order, those within 0.9 R (2^20 of them; the grid holds 1,056,880; smoke mode: 290 x 290
    // holds 66,076 for 2^16); one direction per 4096 consecutive queries, as a renderer that
    // takes one light sample per pass over its pixels.
    points_c.reserve(4 * queries);
    dirs_c.resize(4 * queries);
    const int side = smoke_scaled(1160, 4);
    for (int r = 0; r < side && points_c.size() < 4 * queries; ++r)
      for (int c = 0; c < side && points_c.size() < 4 * queries; ++c) {
        const double x = (c + 0.5) / side * 1.8 - 0.9, z = (r + 0.5) / side * 1.8 - 0.9;
        if (x * x + z * z > 0.81) continue;
        points_c.insert(points_c.end(), {float(l.center[0] + l.radius * x), float(l.center[1]),
                                         float(l.center[2] + l.radius * z), 0.0f});
      }
    for (size_t i = 0; i < queries; i += 4096)
      std::copy(dirs.begin() + 4 * i, dirs.begin() + 4 * i + 4, dirs_c.begin() + 4 * i);
    for (size_t i = 0; i < queries; ++i)
      std::copy(dirs_c.begin() + 4 * (i / 4096 * 4096), dirs_c.begin() + 4 * (i / 4096 * 4096) + 4,
                dirs_c.begin() + 4 * i);
    d_points_c = to_device(points_c);
    d_dirs_c = to_device(dirs_c);
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

// Loads of one texel test: positions[g], offsets[t], offsets[t + 1], one index (last, 4 bytes)
// per binary search step and the found segment's depth (2 bytes; coherent/query.clh,
// sf_coherent_segment_depth); none outside the map.
double texel_bytes(const CompressedStack& c, int x, int y) {
  const int m = c.layout.resolution;
  if (x < 0 || y < 0 || x >= m || y >= m) return 0.0;
  const size_t t = size_t(y) * m + x;
  uint32_t lo = c.offsets[t], hi = c.offsets[t + 1] - 1, steps = 0;
  while (lo < hi) {  // the count of steps depends on the segment count only, not on i
    const uint32_t mid = (lo + hi) / 2;
    hi = mid;
    ++steps;
  }
  return 4.0 + 8.0 + 4.0 * steps + 2.0;
}

// Mean loads per query over a sample of the queries, in double geometry (the device's float
// geometry picks the same texels all but ~1e-3 of the time).
double bytes_per_query(bool filtered, bool coherent) {
  const Fixture& f = fixture();
  const std::vector<float>& points = coherent ? f.points_c : f.points;
  const std::vector<float>& dirs = coherent ? f.dirs_c : f.dirs;
  const StackLayout& l = f.stack.layout;
  constexpr double kPi = 3.14159265358979323846;
  const size_t queries = f.queries, sample = std::min<size_t>(queries, 1 << 16);
  double total = 0.0;
  for (size_t i = 0; i < sample; ++i) {
    const size_t at = i * (queries / sample);  // spread over all of them
    const Vec3 p{points[4 * at], points[4 * at + 1], points[4 * at + 2]};
    const Vec3 d{dirs[4 * at], dirs[4 * at + 1], dirs[4 * at + 2]};
    total += 36.0;  // point, direction, out
    if (!filtered) {
      const uint32_t g = view_of_direction(l, d);
      const ViewPoint vp = project(l, g, p);
      total += texel_bytes(f.host, vp.x, vp.y);
      continue;
    }
    const double t = std::acos(std::clamp(d[1], -1.0, 1.0));
    double ph = std::atan2(d[2], d[0]);
    if (ph < 0) ph += 2 * kPi;
    const double rows = std::clamp(t / kPi * l.views_theta - 0.5, 0.0, double(l.views_theta - 1));
    const int j0 = int(rows), j1 = std::min(j0 + 1, l.views_theta - 1);
    const int k0 = (int(std::floor(ph / (2 * kPi) * l.views_phi - 0.5)) + l.views_phi) % l.views_phi;
    for (int j : {j0, j1})
      for (int k : {k0, (k0 + 1) % l.views_phi}) {
        const ViewFrame fr = view_frame(l, uint32_t(j * l.views_phi + k));
        const Vec3 r = add(p, l.center, -1.0);
        const double x = (dot(r, fr.right) / (2 * l.radius) + 0.5) * l.resolution - 0.5;
        const double y = (dot(r, fr.up) / (2 * l.radius) + 0.5) * l.resolution - 0.5;
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) total += texel_bytes(f.host, x0 + dx, y0 + dy);
      }
  }
  return total / sample;
}

void BM_Query(benchmark::State& state) {
  Fixture& f = fixture();
  const CoherentFilter filter = state.range(0) == 1 ? CoherentFilter::Pcf : CoherentFilter::Nearest;
  const bool coherent = state.range(1) == 1;
  const double bytes = bytes_per_query(filter == CoherentFilter::Pcf, coherent);
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_visibility(runtime(), filter, CoherentToward::Direction, f.queries, f.compressed,
                                     coherent ? f.d_points_c : f.d_points, coherent ? f.d_dirs_c : f.d_dirs, f.d_out);
    e.wait();
    return event_seconds(e);
  });
  state.counters["bytes_per_query"] = bytes;
  state.counters["ns_per_query"] = s * 1e9 / f.queries;
  set_throughput(state, bytes * f.queries, f.queries, s);
}

// The query's geometry alone (coherent/query.clh: the view of the direction, the point's map
// coordinates and depth in it; no stack read): what a nearest query costs at least, the bound
// that says whether the queries wait on memory or on arithmetic.
const char* kGeometrySource = R"CLC(
__kernel void geometry(const sf_coherent_layout L, __global const float4* restrict points,
                       __global const float4* restrict dirs, __global float* restrict out) {
  const uint i = get_global_id(0);
  uint q;
  const float2 uv = sf_coherent_map_coords(L, sf_coherent_view_of(L, dirs[i].xyz), points[i].xyz, &q);
  out[i] = uv.x + uv.y + (float)q;
}
)CLC";

void BM_QueryGeometry(benchmark::State& state) {
  Fixture& f = fixture();
  const bool coherent = state.range(0) == 1;
  cl::Program p(runtime().context(), kernel_source("coherent/query.clh") + kGeometrySource);
  p.build({runtime().device()}, "-cl-std=CL1.2");
  cl::Kernel k(p, "geometry");
  k.setArg(0, sizeof(DeviceLayout), &f.compressed.device);
  k.setArg(1, coherent ? f.d_points_c : f.d_points);
  k.setArg(2, coherent ? f.d_dirs_c : f.d_dirs);
  k.setArg(3, f.d_out);
  const double s = time_runs(state, [&] {
    cl::Event e;
    runtime().queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(f.queries), cl::NullRange, nullptr, &e);
    e.wait();
    return event_seconds(e);
  });
  state.counters["ns_per_query"] = s * 1e9 / f.queries;
  set_throughput(state, 36.0 * f.queries, f.queries, s);
}

// The compression: count + scan + write on the resident stack, with the segments buffer
// allocated beforehand; the time runs from the count's start to the write's end on the device's
// clock, so the read of the total (or the host scan) in between is part of it: the host needs
// the total to size the segments. Per-pass device seconds as counters.
void BM_Compress(benchmark::State& state) {
  Fixture& f = fixture();
  Runtime& rt = runtime();
  const bool host_scan = state.range(0) == 1;
  const StackLayout& l = f.stack.layout;
  const size_t texels = l.texels();
  cl::Buffer offsets = device_buffer((texels + 1) * 4), scratch = device_buffer(compress_scratch_bytes(l));
  cl::Buffer last = device_buffer(f.compressed.segment_count * 4),
             depth = device_buffer(f.compressed.segment_count * 2);
  std::vector<uint32_t> counts(texels + 1);
  double count_s = 0, scan_s = 0, write_s = 0, span_s = 0;
  const double s = time_runs(state, [&] {
    {
      const cl::Event counted = enqueue_compress_count(rt, l, f.device.z1, f.device.z2, offsets);
      EventList after{counted};
      uint64_t total = 0;
      if (host_scan) {
        rt.queue().enqueueReadBuffer(offsets, CL_TRUE, 0, texels * 4, counts.data(), &after);
        for (size_t t = 0; t < texels; ++t) {
          const uint32_t c = counts[t];
          counts[t] = uint32_t(total);
          total += c;
        }
        counts[texels] = uint32_t(total);
        rt.queue().enqueueWriteBuffer(offsets, CL_TRUE, 0, (texels + 1) * 4, counts.data());
        after.clear();
      } else {
        cl::Event first;
        const cl::Event scanned = enqueue_compress_scan(rt, l, offsets, scratch, &first, &after);
        after = {scanned};
        rt.queue().enqueueReadBuffer(scratch, CL_TRUE, compress_total_offset(l), 8, &total, &after);
        scan_s = event_seconds(first, scanned);
      }
      const cl::Event written = enqueue_compress_write(rt, l, f.compressed.segment_count, f.device.z1, f.device.z2,
                                                       offsets, last, depth, after.empty() ? nullptr : &after);
      written.wait();
      count_s = event_seconds(counted);
      write_s = event_seconds(written);
      span_s = event_seconds(counted, written);
      return span_s;
    }
  });
  const double stack_bytes = double(l.views()) * texels * 4;  // z1 + z2
  state.counters["count_ms"] = count_s * 1e3;
  state.counters["scan_ms"] = scan_s * 1e3;
  state.counters["write_ms"] = write_s * 1e3;
  // Between the count's end and the write's start: the scan and the host's read of the total
  // (device scan), or the read, the host's scan and the write of the offsets (host scan).
  state.counters["between_ms"] = (span_s - count_s - write_s) * 1e3;
  state.counters["segments_per_texel"] = double(f.compressed.segment_count) / texels;
  state.counters["ratio"] = double(l.uncompressed_bytes()) / f.host.compressed_bytes();
  set_throughput(state, 2 * stack_bytes + 12.0 * texels + 6.0 * f.compressed.segment_count, double(l.views()) * texels,
                 s);
}

// The scalar reference's compression of the same stack on one host thread, for scale.
void BM_CompressReference(benchmark::State& state) {
  const Fixture& f = fixture();
  const double s = time_runs(
      state, [&] { return wall_seconds([&] { ref::coherent::compress(f.stack); }); }, 1);
  const StackLayout& l = f.stack.layout;
  set_throughput(state, double(l.views()) * l.texels() * 4, double(l.views()) * l.texels(), s);
}

const bool registered = [] {
  const std::string stack = stack_name();
  configure(benchmark::RegisterBenchmark(("coherent/query_" + stack).c_str(), BM_Query))
      ->ArgNames({"filter", "rx"})
      ->ArgsProduct({{0, 1}, {0, 1}});
  configure(benchmark::RegisterBenchmark("coherent/query_geometry_bound", BM_QueryGeometry))
      ->ArgName("rx")
      ->Arg(0)
      ->Arg(1);
  configure(benchmark::RegisterBenchmark(("coherent/compress_" + stack).c_str(), BM_Compress))
      ->ArgName("scan")
      ->Arg(0)
      ->Arg(1);
  configure(benchmark::RegisterBenchmark(("coherent/compress_reference_" + stack).c_str(), BM_CompressReference))
      ->Repetitions(std::min(2, repetitions()));
  return true;
}();

}  // namespace
}  // namespace sf::bench

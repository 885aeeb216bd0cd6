// 8. Beyond the per-kernel suites: every reconstruction (each method x each
// lookup: bilinear, trilinear mips, SAT box), the z-min pyramid and the ESM failure
// classification (zmax, threshold) at 512, 2048 and 4096 maps (smoke mode: 512), and the scalar
// double reference of the transform, the mip chain, the SAT and s_ref in the same binary.
// Receivers: 512x512 random points with footprints 1..64 texels (log-uniform), so every LOD is
// read; tables built once outside the timing. csm at order 4 (8 channels: a 4096 SAT of order 8
// would need 2 GiB). Bytes per receiver: u, v, d, f read + v written, plus the taps the lookup
// must read (bilinear 4, trilinear 8, box 4 float-float corners = 8 values) per basis channel.
#include <algorithm>
#include <cmath>

#include "bench_common.hpp"
#include "lookups.hpp"
#include "reference.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/classify.hpp"

namespace sf::bench {
namespace {

constexpr size_t kRxSide = 512, kRx = kRxSide * kRxSide;
constexpr int kRefSize = 512;

FilterOptions options_for(const std::string& method) {
  FilterOptions o;
  o.method = method;
  o.csm.order = 4;
  o.blur.radius = method == "pcf" ? 3 : 0;  // pcf's support (sm: the 2x2 bilinear test)
  return o;
}

struct RandomReceivers {
  cl::Buffer u, v, d, f, vis;
  RandomReceivers() {
    u = to_device(random_floats(kRx, 21));
    v = to_device(random_floats(kRx, 22));
    d = to_device(random_floats(kRx, 23));
    std::vector<float> fp = random_floats(kRx, 24, 0.0f, 6.0f);
    for (auto& x : fp) x = std::exp2(x);
    f = to_device(fp);
    vis = device_buffer(kRx * sizeof(float));
  }
};
const RandomReceivers& receivers() {
  static RandomReceivers r;
  return r;
}

void BM_ReconstructLookup(benchmark::State& state, std::string method) {
  const int n = int(state.range(0));
  const Lookup kind = static_cast<Lookup>(state.range(1));
  const FilterOptions opt = options_for(method);
  const MethodDesc& m = *sf::method(method);
  const RandomReceivers& rx = receivers();
  cl::Buffer depth = to_device(random_floats(size_t(n) * n, 25, 0.2f, 0.8f));
  if (m.raw_depth) {
    const double s = time_runs(state, [&] {
      cl::Event e =
          enqueue_pcf_points(runtime(), opt, n, n, kRx, 0, depth, rx.u, rx.v, rx.d, cl::Buffer(), cl::Buffer(), rx.vis);
      e.wait();
      return event_seconds(e);
    });
    const double taps = method == "sm" ? 4.0 : std::pow(2.0 * opt.blur.radius + 2.0, 2.0);
    set_throughput(state, (16.0 + 4.0 * taps) * kRx, double(kRx), s);
    return;
  }
  const int ch = m.channels(opt);
  const ImageShape shape{n, n, ch, 4};
  cl::Buffer basis = device_buffer(shape.bytes());
  enqueue_transform(runtime(), m, opt, n, n, depth, basis).wait();
  const LookupBuffers lk = lookup_tables(kind, basis, shape, rx.f);
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_reconstruct_points(runtime(), m, opt, n, n, kRx, 0, basis, &lk, rx.u, rx.v, rx.d, rx.vis);
    e.wait();
    return event_seconds(e);
  });
  const double taps = kind == Lookup::Bilinear ? 4.0 : 8.0;
  state.counters["channels"] = ch;
  set_throughput(state, (20.0 + 4.0 * taps * ch) * kRx, double(kRx), s);
}

// The z-min pyramid of the raw depth (ssmm's blocker search); mean and z-max: bench_pyramid.cpp.
void BM_ZMinChain(benchmark::State& state) {
  time_chain(state, Reduce::Min, ImageShape{int(state.range(0)), int(state.range(0)), 1, 4}, 26);
}

// ESM failure classification (mode 1 zmax, 2 threshold) of the random receivers after an esm
// reconstruction with trilinear mips; the basis, its chain and the z-max pyramid are built once.
// Bytes per receiver: u, v, d, f, visibility read and visibility written (24), one flag byte.
void BM_EsmClassify(benchmark::State& state) {
  const int n = int(state.range(0));
  FilterOptions opt;  // esm, c = 80
  opt.esm_classify.mode = state.range(1) == 1 ? EsmClassify::ZMax : EsmClassify::Threshold;
  opt.lookup.kind = Lookup::Mips;
  const MethodDesc& esm = *sf::method("esm");
  const RandomReceivers& rx = receivers();
  const ImageShape shape{n, n, 1, 4};
  ClassifyInputs in;
  in.width = in.height = n;
  in.depth = to_device(random_floats(shape.plane_texels(), 27, 0.2f, 0.8f));
  in.basis = device_buffer(shape.bytes());
  enqueue_transform(runtime(), esm, opt, n, n, in.depth, in.basis).wait();
  in.lookup = lookup_tables(Lookup::Mips, in.basis, shape, rx.f);
  if (opt.esm_classify.mode == EsmClassify::ZMax) {
    in.zmax_chain = device_buffer(std::max<size_t>(mip_layout(n, n, 1).chain_values, 1) * sizeof(float));
    if (const size_t base = zmax_base_bytes(opt, n, n)) in.zmax_base = device_buffer(base);
    enqueue_zmax_pyramid(runtime(), opt, n, n, in.depth, in.zmax_base, in.zmax_chain).wait();
  }
  enqueue_reconstruct_points(runtime(), esm, opt, n, n, kRx, 0, in.basis, &in.lookup, rx.u, rx.v, rx.d, rx.vis).wait();
  cl::Buffer flags = device_buffer(kRx);
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_esm_classify_points(runtime(), opt, kRx, 0, in, rx.u, rx.v, rx.d, rx.vis, flags);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, 25.0 * kRx, double(kRx), s);
}

HostImage random_depth(int n, unsigned seed) {
  HostImage img(n, n, 1);
  const auto v = random_floats(size_t(n) * n, seed, 0.2f, 0.8f);
  img.data.assign(v.begin(), v.end());
  return img;
}

ref::Planes planes_of(const HostImage& img) {
  ref::Planes p(img.width, img.height, 1);
  p.data.assign(img.data.begin(), img.data.end());
  return p;
}

// Host wall time of the scalar reference (one thread, double precision).
void BM_RefTransform(benchmark::State& state, std::string method) {
  const HostImage depth = random_depth(kRefSize, 31);
  const FilterOptions opt = options_for(method);
  const int ch = sf::method(method)->channels(opt);
  const double s = time_runs(
      state, [&] { return wall_seconds([&] { benchmark::DoNotOptimize(ref::transform(opt, depth)); }); }, 1);
  set_throughput(state, 4.0 * (1.0 + ch) * depth.texels(), double(depth.texels()), s);
}

void BM_RefMips(benchmark::State& state) {
  const ref::Planes p = planes_of(random_depth(kRefSize, 32));
  const double s = time_runs(
      state, [&] { return wall_seconds([&] { benchmark::DoNotOptimize(ref::mip_chain(p, 0)); }); }, 1);
  set_throughput(state, 4.0 * p.data.size() * (1.0 + 1.0 / 3.0), double(p.data.size()), s);
}

void BM_RefSat(benchmark::State& state) {
  const ref::Planes p = planes_of(random_depth(kRefSize, 33));
  const double s = time_runs(
      state, [&] { return wall_seconds([&] { benchmark::DoNotOptimize(ref::sat_table(p)); }); }, 1);
  set_throughput(state, 12.0 * p.data.size(), double(p.data.size()), s);
}

// s_ref (the exact filtered test) of 128x128 random receivers under Gaussian R = 3 + bilinear.
void BM_RefSref(benchmark::State& state) {
  const HostImage depth = random_depth(kRefSize, 34);
  sf::Receivers rx;
  rx.width = rx.height = 128;
  rx.u = random_floats(128 * 128, 35);
  rx.v = random_floats(128 * 128, 36);
  rx.d = random_floats(128 * 128, 37);
  BlurOptions blur;
  blur.radius = 3;
  const double s = time_runs(
      state,
      [&] { return wall_seconds([&] { benchmark::DoNotOptimize(ref::s_ref(depth, blur, Lookup::Bilinear, rx)); }); },
      1);
  set_throughput(state, (16.0 + 4.0 * 64) * rx.count(), double(rx.count()), s);
}

// 69 device benchmarks: at most 3 repetitions keeps `make bench` within its budget.
int reps() { return std::min(3, repetitions()); }

}  // namespace

void register_coverage() {
  for (const auto& m : methods()) {
    auto* b =
        configure(benchmark::RegisterBenchmark(("reconstruct_lookup/" + m.name).c_str(), BM_ReconstructLookup, m.name))
            ->Repetitions(reps())
            ->ArgNames({"size", "lookup"});  // lookup: 0 bilinear, 1 mips, 2 sat
    for (int64_t size : sizes({512, 2048, 4096}))
      for (int64_t lookup : {0, 1, 2})
        if (!m.raw_depth || lookup == 0) b->Args({size, lookup});
  }
  configure(benchmark::RegisterBenchmark("mips/zmin_chain", BM_ZMinChain))
      ->Repetitions(reps())
      ->ArgName("size")
      ->ArgsProduct({sizes({512, 2048, 4096})});
  configure(benchmark::RegisterBenchmark("esm_classify/points_512x512", BM_EsmClassify))
      ->Repetitions(reps())
      ->ArgNames({"size", "mode"})  // mode: 1 zmax, 2 threshold
      ->ArgsProduct({sizes({512, 2048, 4096}), {1, 2}});
  for (const auto& m : methods())
    if (!m.raw_depth)
      configure(benchmark::RegisterBenchmark(("reference/transform/" + m.name).c_str(), BM_RefTransform, m.name))
          ->Repetitions(reps())
          ->ArgName("size")
          ->Arg(kRefSize);
  configure(benchmark::RegisterBenchmark("reference/mips", BM_RefMips))
      ->Repetitions(reps())
      ->ArgName("size")
      ->Arg(kRefSize);
  configure(benchmark::RegisterBenchmark("reference/sat", BM_RefSat))
      ->Repetitions(reps())
      ->ArgName("size")
      ->Arg(kRefSize);
  configure(benchmark::RegisterBenchmark("reference/s_ref_R3_128x128", BM_RefSref))
      ->Repetitions(reps())
      ->ArgName("size")
      ->Arg(kRefSize);
}

}  // namespace sf::bench

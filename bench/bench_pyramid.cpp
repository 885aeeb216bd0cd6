// 6. Footprint lookups: the mip chain and the summed-area table of a 2048x2048 basis
// with 1 and 4 channels, and trilinear / box vs bilinear ESM reconstruction of 1920x1080 random
// receivers on a 2048x2048 map. Smoke mode: sizes() of each list, smoke_size(2048) and screen().
// Bytes: mips = level 0 read + every level written (4 * N * (W H + chain)); sat = the image read
// + the float-float table written (4 N W H + 8 N (W+1)(H+1)), the least any SAT build moves.
#include <cmath>
#include <string>

#include "bench_common.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf::bench {
namespace {

constexpr int kMap = 2048;

void BM_MipChain(benchmark::State& state) {
  const int n = int(state.range(0));
  time_chain(state, Reduce::Mean, ImageShape{n, n, int(state.range(1)), 4}, 11);
}

void BM_ZMaxChain(benchmark::State& state) {
  const int n = int(state.range(0));
  time_chain(state, Reduce::Max, ImageShape{n, n, 1, 4}, 12);
}

void BM_Sat(benchmark::State& state) {
  const int n = int(state.range(0)), channels = int(state.range(1));
  const ImageShape shape{n, n, channels, 4};
  const SatLayout L = sat_layout(shape);
  cl::Buffer src = to_device(random_floats(shape.plane_texels() * channels, 13));
  cl::Buffer table = device_buffer(L.table_floats * sizeof(float));
  cl::Buffer bands = device_buffer(L.band_floats * sizeof(float));
  const double s = time_runs(state, [&] {
    cl::Event first;
    const cl::Event last = enqueue_sat(runtime(), Storage::F32, {}, {}, shape, src, table, bands, &first);
    last.wait();
    return event_seconds(first, last);
  });
  set_throughput(state, (4.0 * double(shape.plane_texels()) + 8.0 * (n + 1.0) * (n + 1.0)) * channels,
                 double(shape.plane_texels()) * channels, s);
}

// ESM reconstruction with each lookup (the tables built once, outside the timing). rx 0: random
// receivers, footprints 1 .. 64 texels (every LOD; each lookup misses the caches: the box reads
// 16 lines of the 2 x 16 MB table, the trilinear lookup level 0 or 1 a third of the time);
// rx 1: bench_pipeline's coherent camera sweep (footprints 0.6 .. 5 texels).
void BM_ReconstructLookup(benchmark::State& state) {
  const Lookup kind = static_cast<Lookup>(state.range(0));
  const int n = smoke_size(kMap);
  const size_t count = screen().count();
  const ImageShape shape{n, n, 1, 4};
  FilterOptions opt;
  cl::Buffer depth = to_device(random_floats(shape.plane_texels(), 4, 0.2f, 0.8f));
  cl::Buffer basis = device_buffer(shape.bytes());
  enqueue_transform(runtime(), *sf::method("esm"), opt, n, n, depth, basis).wait();
  std::vector<float> hu, hv, hd, f;
  if (state.range(1) == 1) {
    coherent_receivers(n, hu, hv, hd, f);
  } else {
    // Footprints 1 .. 64 texels (log-uniform): every LOD of a typical camera view.
    f = random_floats(count, 8, 0.0f, 6.0f);
    for (auto& x : f) x = std::exp2(x);
    hu = random_floats(count, 5), hv = random_floats(count, 6), hd = random_floats(count, 7);
  }
  const LookupBuffers lk = lookup_tables(kind, basis, shape, to_device(f));
  cl::Buffer u = to_device(hu), v = to_device(hv), d = to_device(hd);
  cl::Buffer vis = device_buffer(count * sizeof(float));
  const double s = time_runs(state, [&] {
    cl::Event e =
        enqueue_reconstruct_points(runtime(), *sf::method("esm"), opt, n, n, count, 0, basis, &lk, u, v, d, vis);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, (kind == Lookup::Bilinear ? 4.0 : 5.0) * sizeof(float) * count, count, s);
}

}  // namespace

void register_pyramid() {
  auto* chain = configure(benchmark::RegisterBenchmark("mips/chain", BM_MipChain))->ArgNames({"size", "channels"});
  for (int64_t size : sizes({512, kMap, 4096})) chain->Args({size, 1})->Args({size, 4});
  configure(benchmark::RegisterBenchmark("mips/zmax_chain", BM_ZMaxChain))
      ->ArgName("size")
      ->ArgsProduct({sizes({512, kMap, 4096})});
  auto* sat = configure(benchmark::RegisterBenchmark("sat/table", BM_Sat))->ArgNames({"size", "channels"});
  for (int64_t size : sizes({512, kMap, 4096})) sat->Args({size, 1})->Args({size, 4});
  const std::string name = "esm_reconstruct/lookup_" + screen().name() + "_on_" + std::to_string(smoke_size(kMap));
  configure(benchmark::RegisterBenchmark(name.c_str(), BM_ReconstructLookup))
      ->ArgNames({"lookup", "rx"})  // lookup 0 bilinear, 1 mips (trilinear), 2 sat (box)
      ->ArgsProduct({{0, 1, 2}, {0, 1}});
}

}  // namespace sf::bench

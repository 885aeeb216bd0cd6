// 5. The full ESM pipeline through sf::Pipeline: 2048x2048 depth, c = 80, blur R = 3, then
// 1920x1080 random receivers. Device time = transform + blur + reconstruct (profiling events),
// per-stage times as counters. Bytes: 8 per map texel (transform) + 16 (blur) + 16 per receiver.
#include "bench_common.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::bench {
namespace {

void BM_EsmPipeline(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  const size_t texels = size_t(n) * n, count = 1920 * 1080;
  FilterOptions opt;
  opt.blur.radius = radius;
  Pipeline pipe(runtime_ptr(), opt, n, n);
  cl::Buffer depth = to_device(random_floats(texels, 9));
  DeviceReceivers rx;
  rx.count = count;
  rx.u = to_device(random_floats(count, 10));
  rx.v = to_device(random_floats(count, 11));
  rx.d = to_device(random_floats(count, 12));
  cl::Buffer vis = device_buffer(count * sizeof(float));
  StageTimes sum;
  int runs = 0;
  const double s = time_runs(state, [&] {
    EventList filtered{pipe.prefilter(depth)};
    pipe.reconstruct(rx, vis, &filtered).wait();
    const StageTimes t = pipe.times();
    sum.transform += t.transform;
    sum.blur += t.blur;
    sum.reconstruct += t.reconstruct;
    ++runs;
    return t.transform + t.blur + t.reconstruct;
  });
  state.counters["transform_ms"] = 1e3 * sum.transform / runs;
  state.counters["blur_ms"] = 1e3 * sum.blur / runs;
  state.counters["reconstruct_ms"] = 1e3 * sum.reconstruct / runs;
  set_throughput(state, 24.0 * texels + 16.0 * count, texels, s);
}

}  // namespace

void register_pipeline() {
  configure(benchmark::RegisterBenchmark("esm_pipeline/points_1920x1080", BM_EsmPipeline))
      ->ArgNames({"size", "R"})
      ->Args({2048, 3});
}

}  // namespace sf::bench

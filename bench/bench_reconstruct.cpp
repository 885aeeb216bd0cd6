// 4. ESM reconstruction on a 2048x2048 filtered basis: 1920x1080 random receivers (points
// mode: u, v, d read + visibility written = 16 bytes per receiver, plus the bilinear gathers)
// and grid mode at 2048x2048 (d and one basis texel read + visibility written = 12 bytes).
#include "bench_common.hpp"
#include "shadowfilter/kernels.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::bench {
namespace {

constexpr int kMapSize = 2048;

struct Basis {
  cl::Buffer buf = device_buffer(size_t(kMapSize) * kMapSize * sizeof(float));
  Basis() {
    cl::Buffer depth = to_device(random_floats(size_t(kMapSize) * kMapSize, 4, 0.2f, 0.8f));
    const FilterOptions esm;  // c = 80
    enqueue_transform(runtime(), find_method("esm"), esm, depth, kMapSize, kMapSize, buf).wait();
  }
};

const cl::Buffer& basis() {
  static Basis b;
  return b.buf;
}

void BM_ReconstructPoints(benchmark::State& state) {
  const size_t count = size_t(state.range(0)) * state.range(1);
  cl::Buffer u = to_device(random_floats(count, 5)), v = to_device(random_floats(count, 6));
  cl::Buffer d = to_device(random_floats(count, 7));
  cl::Buffer vis = device_buffer(count * sizeof(float));
  const FilterOptions opt;
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_reconstruct_points(runtime(), find_method("esm"), opt, basis(), kMapSize,
                                             kMapSize, u, v, d, vis, count);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, 4.0 * sizeof(float) * count, count, s);
}

void BM_ReconstructGrid(benchmark::State& state) {
  const size_t count = size_t(kMapSize) * kMapSize;
  cl::Buffer d = to_device(random_floats(count, 8));
  cl::Buffer vis = device_buffer(count * sizeof(float));
  const FilterOptions opt;
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_reconstruct_grid(runtime(), find_method("esm"), opt, basis(), kMapSize,
                                           kMapSize, d, vis);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, 3.0 * sizeof(float) * count, count, s);
}

}  // namespace

void register_reconstruct() {
  configure(benchmark::RegisterBenchmark("esm_reconstruct/points_on_2048", BM_ReconstructPoints))
      ->ArgNames({"w", "h"})
      ->Args({1920, 1080});
  configure(benchmark::RegisterBenchmark("esm_reconstruct/grid", BM_ReconstructGrid))
      ->ArgName("size")
      ->Arg(kMapSize);
}

}  // namespace sf::bench

// 2. ESM basis transform, depth -> exp(c (z - 1/2)): 1 float read + 1 float written per texel,
// at three map sizes, with explicit float16 vectors (sf_transformv, the default) and with one
// texel per work-item (vector width 1). Every method and storage: bench_methods.cpp.
#include "bench_common.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::bench {
namespace {

// Args: map size, transform vector width.
void BM_EsmTransform(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const size_t texels = size_t(n) * n;
  FilterOptions opt;  // esm, c = 80
  opt.schedule.transform_vector_width = static_cast<int>(state.range(1));
  const MethodDesc& esm = *sf::method("esm");
  cl::Buffer depth = to_device(random_floats(texels, 2));
  cl::Buffer basis = device_buffer(texels * sizeof(float));
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_transform(runtime(), esm, opt, n, n, depth, basis);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, 2.0 * sizeof(float) * texels, texels, s);
}

}  // namespace

void register_transform() {
  configure(benchmark::RegisterBenchmark("esm_transform", BM_EsmTransform))
      ->ArgNames({"size", "vec"})
      ->ArgsProduct({sizes({512, 2048, 4096}), {1, 16}});
}

}  // namespace sf::bench

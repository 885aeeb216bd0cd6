// 3. Separable Gaussian blur of one float channel (rows then columns, clamp-to-edge):
// ours on the device at several sizes and radii, and the scalar double reference at 512x512.
// Bytes per texel: 2 reads + 2 writes (both passes, whatever a kernel really moves).
// Counters: kernel_ms (the fused blur kernel), copy_ms (in place: the copy back from tmp) and
// wall_ms (host time from enqueue to completion, launch overheads included: what a caller
// waiting on the result sees).
#include "bench_common.hpp"
#include "reference.hpp"
#include "shadowfilter/kernels.hpp"

namespace sf::bench {
namespace {

constexpr double kBlurBytesPerTexel = 4.0 * sizeof(float);

// Out of place (src -> dst, tmp unused by the fused kernel) or in place (src -> src through tmp,
// as the pipeline runs it).
void BM_Blur(benchmark::State& state, bool in_place) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  const ImageShape shape{n, n, 1};
  cl::Buffer src = to_device(random_floats(shape.plane_texels(), 3));
  cl::Buffer tmp = device_buffer(shape.bytes());
  cl::Buffer dst = in_place ? src : device_buffer(shape.bytes());
  const BlurOptions blur{radius, 0.0f};
  const ScheduleOptions sched;
  double kernel = 0, copy = 0, wall = 0;
  int runs = 0;
  const double s = time_runs(state, [&] {
    BlurEvents ev;
    wall += wall_seconds([&] {
      ev = enqueue_blur(runtime(), blur, sched, src, tmp, dst, shape);
      ev.cols.wait();
    });
    kernel += event_seconds(ev.rows);
    if (in_place) copy += event_seconds(ev.cols);
    ++runs;
    return event_seconds(ev.rows, ev.cols);
  });
  state.counters["kernel_ms"] = 1e3 * kernel / runs;
  if (in_place) state.counters["copy_ms"] = 1e3 * copy / runs;
  state.counters["wall_ms"] = 1e3 * wall / runs;
  set_throughput(state, kBlurBytesPerTexel * shape.plane_texels(), shape.plane_texels(), s);
}

void BM_ReferenceBlur(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  ref::Planes in(n, n, 1);
  const auto values = random_floats(in.data.size(), 3);
  in.data.assign(values.begin(), values.end());
  const double s = time_runs(
      state,
      [&] {
        return wall_seconds([&] { benchmark::DoNotOptimize(ref::blur(in, radius, 0.0)); });
      },
      1);
  set_throughput(state, kBlurBytesPerTexel * in.data.size(), in.data.size(), s);
}

const std::vector<int64_t> kRadii = {1, 3, 7, 15, 31};

}  // namespace

void register_blur() {
  for (int size : {512, 2048, 4096}) {
    for (int64_t radius : kRadii) {
      configure(benchmark::RegisterBenchmark("blur/ours", BM_Blur, false))
          ->ArgNames({"size", "R"})
          ->Args({size, radius});
#ifdef SF_HAVE_OPENCV
      register_opencv_blur(size, static_cast<int>(radius));
#endif
    }
  }
  configure(benchmark::RegisterBenchmark("blur/ours_in_place", BM_Blur, true))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({{2048}, kRadii});
  configure(benchmark::RegisterBenchmark("blur/reference_double", BM_ReferenceBlur))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({{512}, kRadii});
}

}  // namespace sf::bench

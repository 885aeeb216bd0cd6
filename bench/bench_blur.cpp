// 3. Separable Gaussian blur of one float channel (rows then columns, clamp-to-edge):
// ours on the device at several sizes and radii, and the scalar double reference at 512x512.
// Bytes per texel: 2 reads + 2 writes (both passes, whatever a kernel really moves).
// Counters: rows_ms / cols_ms (device time per pass) and wall_ms (host time from enqueue to
// completion, launch overheads included: what a caller waiting on the result sees).
#include "bench_common.hpp"
#include "reference.hpp"
#include "shadowfilter/kernels.hpp"

namespace sf::bench {
namespace {

constexpr double kBlurBytesPerTexel = 4.0 * sizeof(float);

void BM_Blur(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  const ImageShape shape{n, n, 1};
  cl::Buffer src = to_device(random_floats(shape.plane_texels(), 3));
  cl::Buffer tmp = device_buffer(shape.bytes()), dst = device_buffer(shape.bytes());
  const BlurOptions blur{radius, 0.0f};
  const ScheduleOptions sched;
  double rows = 0, cols = 0, wall = 0;
  int runs = 0;
  const double s = time_runs(state, [&] {
    BlurEvents ev;
    wall += wall_seconds([&] {
      ev = enqueue_blur(runtime(), blur, sched, src, tmp, dst, shape);
      ev.cols.wait();
    });
    rows += event_seconds(ev.rows);
    cols += event_seconds(ev.cols);
    ++runs;
    return event_seconds(ev.rows, ev.cols);
  });
  state.counters["rows_ms"] = 1e3 * rows / runs;
  state.counters["cols_ms"] = 1e3 * cols / runs;
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
  configure(benchmark::RegisterBenchmark("blur/ours", BM_Blur))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({{512, 2048, 4096}, kRadii});
  configure(benchmark::RegisterBenchmark("blur/reference_double", BM_ReferenceBlur))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({{512}, kRadii});
}

}  // namespace sf::bench

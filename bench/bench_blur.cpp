// 3. Separable Gaussian blur of one channel (rows then columns, clamp-to-edge): ours on the
// device at several sizes and radii (float32; and f16 / unorm16 / unorm8 storage at 2048^2),
// and the scalar double reference (one thread) at 512x512 and 2048x2048.
// Bytes per texel: 2 reads + 2 writes of the stored value (both passes, whatever a kernel really
// moves): 16 for f32, 8 for f16 / unorm16, 4 for unorm8, so bw_fraction of the narrow formats
// is not their speed-up; compare kernel_ms (or Mtexel/s) with blur/ours at the same size and R.
// Counters: kernel_ms (the fused blur kernel), copy_ms (in place: the copy back from tmp) and
// wall_ms (host time from enqueue to completion, launch overheads included: what a caller
// waiting on the result sees).
#include <algorithm>
#include <cstring>
#include <random>

#include "bench_common.hpp"
#include "reference.hpp"
#include "shadowfilter/blur.hpp"

namespace sf::bench {
namespace {

constexpr double kBlurPassBytes = 4.0;  // 2 reads + 2 writes per texel

// Random stored values in [0.05, 1] (f16 codes of [0.5, 1): no subnormal arithmetic).
cl::Buffer random_stored(Storage st, size_t count, unsigned seed) {
  if (st == Storage::F32) return to_device(random_floats(count, seed, 0.05f, 1.0f));
  std::mt19937 rng(seed);
  std::vector<uint8_t> raw(count * storage_bytes(st));
  for (size_t i = 0; i < count; ++i) {
    uint16_t code = static_cast<uint16_t>(rng());
    if (st == Storage::F16) code = 0x3800 | (code & 0x3ff);
    std::memcpy(&raw[i * storage_bytes(st)], &code, storage_bytes(st));
  }
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, raw.size(), raw.data());
}

// Out of place (src -> dst, tmp unused by the fused kernel) or in place (src -> src through tmp,
// as the pipeline runs it).
void BM_Blur(benchmark::State& state, bool in_place, Storage storage) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  const ImageShape shape{n, n, 1, storage_bytes(storage)};
  cl::Buffer src = random_stored(storage, shape.plane_texels(), 3);
  cl::Buffer tmp = device_buffer(shape.bytes());
  cl::Buffer dst = in_place ? src : device_buffer(shape.bytes());
  const BlurOptions blur{radius, 0.0f};
  const ScheduleOptions sched;
  double kernel = 0, copy = 0, wall = 0;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        cl::Event first, last;
        wall += wall_seconds([&] {
          last = enqueue_blur(runtime(), blur, sched, storage, shape, src, tmp, dst, &first);
          last.wait();
        });
        kernel += event_seconds(first);
        if (in_place) copy += event_seconds(last);
        ++runs;
        return event_seconds(first, last);
      },
      2, [&] { kernel = copy = wall = 0, runs = 0; });
  state.counters["kernel_ms"] = 1e3 * kernel / runs;
  if (in_place) state.counters["copy_ms"] = 1e3 * copy / runs;
  state.counters["wall_ms"] = 1e3 * wall / runs;
  set_throughput(state, kBlurPassBytes * shape.value_bytes * shape.plane_texels(), shape.plane_texels(), s);
}

// The max filter (enqueue_max_filter: the blur's kernels taking the max, the ESM classification's
// dilated z-max) beside the blur of the same size and radius: the same bytes.
void BM_MaxFilter(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ImageShape shape{n, n, 1, 4};
  cl::Buffer src = random_stored(Storage::F32, shape.plane_texels(), 3), dst = device_buffer(shape.bytes());
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_max_filter(runtime(), static_cast<int>(state.range(1)), {}, shape, src, dst);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, kBlurPassBytes * sizeof(float) * shape.plane_texels(), shape.plane_texels(), s);
}

void BM_ReferenceBlur(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  ref::Planes in(n, n, 1);
  const auto values = random_floats(in.data.size(), 3);
  in.data.assign(values.begin(), values.end());
  const double s = time_runs(
      state, [&] { return wall_seconds([&] { benchmark::DoNotOptimize(ref::blur(in, radius, 0.0)); }); },
      n > 512 ? 0 : 1);  // host code: no kernel to build; seconds a run at 2048
  set_throughput(state, kBlurPassBytes * sizeof(float) * in.data.size(), in.data.size(), s);
}

const std::vector<int64_t> kRadii = {1, 3, 7, 15, 31};

}  // namespace

void register_blur() {
  for (int64_t size : sizes({512, 2048, 4096})) {
    for (int64_t radius : kRadii) {
      configure(benchmark::RegisterBenchmark("blur/ours", BM_Blur, false, Storage::F32))
          ->ArgNames({"size", "R"})
          ->Args({size, radius});
      configure(benchmark::RegisterBenchmark("blur/max_filter", BM_MaxFilter))
          ->ArgNames({"size", "R"})
          ->Args({size, radius});
#ifdef SF_HAVE_OPENCV
      register_opencv_blur(static_cast<int>(size), static_cast<int>(radius));
#endif
    }
  }
  configure(benchmark::RegisterBenchmark("blur/ours_in_place", BM_Blur, true, Storage::F32))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({sizes({2048}), kRadii});
  for (Storage st : {Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
    for (bool in_place : {false, true})
      configure(benchmark::RegisterBenchmark(
                    (std::string("blur/ours") + (in_place ? "_in_place_" : "_") + storage_name(st)).c_str(), BM_Blur,
                    in_place, st))
          ->ArgNames({"size", "R"})
          ->ArgsProduct({sizes({2048}), {3, 15}});
  }
  configure(benchmark::RegisterBenchmark("blur/reference_double", BM_ReferenceBlur))
      ->ArgNames({"size", "R"})
      ->ArgsProduct({sizes({512}), kRadii});
  // 2048: 6 s a run at R = 31 on the loaded machine; 4096 (4x that) is left out. Not in smoke
  // mode: the same function at the same radii runs at 512 above.
  if (!smoke())
    configure(benchmark::RegisterBenchmark("blur/reference_double", BM_ReferenceBlur))
        ->Repetitions(std::min(2, repetitions()))
        ->ArgNames({"size", "R"})
        ->ArgsProduct({{2048}, kRadii});
}

}  // namespace sf::bench

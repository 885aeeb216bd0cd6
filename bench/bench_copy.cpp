// 1. Device copy bandwidth of a 64 MiB buffer: clEnqueueCopyBuffer, a trivial copy kernel
// dst[i] = src[i], and the same with float16 per work-item. The best median is the reference
// bandwidth of every bw_fraction (bytes = 1 read + 1 write per float).
#include <algorithm>

#include "bench_common.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::bench {
namespace {

constexpr size_t kCopyBytes = size_t(64) << 20;
constexpr size_t kCopyFloats = kCopyBytes / sizeof(float);

const char* kCopySource = R"CL(
__kernel void copy1(__global const float* restrict src, __global float* restrict dst) {
  const size_t i = get_global_id(0);
  dst[i] = src[i];
}
__kernel void copy16(__global const float16* restrict src, __global float16* restrict dst) {
  const size_t i = get_global_id(0);
  dst[i] = src[i];
}
)CL";

struct CopyBuffers {
  cl::Buffer src = to_device(random_floats(kCopyFloats, 1));
  cl::Buffer dst = device_buffer(kCopyBytes);
};

CopyBuffers& buffers() {
  static CopyBuffers b;
  return b;
}

cl::Kernel copy_kernel(const char* name) {
  static cl::Program p = [] {
    cl::Program prog(runtime().context(), kCopySource);
    prog.build({runtime().device()}, "-cl-std=CL1.2");
    return prog;
  }();
  cl::Kernel k(p, name);
  k.setArg(0, buffers().src);
  k.setArg(1, buffers().dst);
  return k;
}

double copy_buffer_once() {
  cl::Event e;
  runtime().queue().enqueueCopyBuffer(buffers().src, buffers().dst, 0, 0, kCopyBytes, nullptr, &e);
  e.wait();
  return event_seconds(e);
}

TimedRun copy_kernel_run(const char* name, size_t floats_per_item) {
  cl::Kernel k = copy_kernel(name);
  return [k, floats_per_item]() mutable {
    cl::Event e;
    runtime().queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(kCopyFloats / floats_per_item), cl::NullRange,
                                           nullptr, &e);
    e.wait();
    return event_seconds(e);
  };
}

void BM_CopyBuffer(benchmark::State& state) {
  const double s = time_runs(state, copy_buffer_once);
  set_throughput(state, 2.0 * kCopyBytes, kCopyFloats, s);
}

void BM_CopyKernel(benchmark::State& state, const char* name, size_t floats_per_item) {
  const double s = time_runs(state, copy_kernel_run(name, floats_per_item));
  set_throughput(state, 2.0 * kCopyBytes, kCopyFloats, s);
}

}  // namespace

double measure_copy_bandwidth() {
  constexpr int kRuns = 31, kWarmups = 8;  // the first runs fault pages in and wake PoCL's threads
  const double best = std::min({median_seconds(copy_buffer_once, kRuns, kWarmups),
                                median_seconds(copy_kernel_run("copy1", 1), kRuns, kWarmups),
                                median_seconds(copy_kernel_run("copy16", 16), kRuns, kWarmups)});
  return 2.0 * kCopyBytes / best;
}

void register_copy() {
  configure(benchmark::RegisterBenchmark("copy/clEnqueueCopyBuffer/64MiB", BM_CopyBuffer));
  configure(benchmark::RegisterBenchmark("copy/kernel_float/64MiB", BM_CopyKernel, "copy1", 1));
  configure(benchmark::RegisterBenchmark("copy/kernel_float16/64MiB", BM_CopyKernel, "copy16", 16));
}

}  // namespace sf::bench

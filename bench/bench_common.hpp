#pragma once
// Shared pieces of sf_bench: one OpenCL runtime, the reference copy bandwidth, timing loops
// that report device (or host) seconds as manual time, and the throughput counters.
#include <benchmark/benchmark.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::bench {

Runtime& runtime();
std::shared_ptr<Runtime> runtime_ptr();

// Device copy bandwidth in bytes/s (read + written bytes per second), the denominator of
// every bw_fraction counter; set once by main before the benchmarks run.
double reference_bandwidth();
void set_reference_bandwidth(double bytes_per_second);

// One timed run: enqueues, waits, returns the seconds it took (device time from profiling
// events, or host wall time for CPU baselines).
using TimedRun = std::function<double()>;
// Warm-up runs, then one run per benchmark iteration, reported with SetIterationTime.
// Returns the mean seconds of the timed runs. `warmed`, when given, is called between the
// warm-ups and the timed runs: a run that sums counters resets them there, so that they hold
// the timed runs only (PoCL compiles a kernel for its launch shape at the first launch, inside
// that launch's profiled time).
double time_runs(benchmark::State& state, const TimedRun& run, int warmups = 2,
                 const std::function<void()>& warmed = nullptr);
// Median of `runs` timed runs after `warmups` (for values needed outside a benchmark).
double median_seconds(const TimedRun& run, int runs, int warmups = 2);
// Host wall seconds of one call.
double wall_seconds(const std::function<void()>& work);

// bytes_per_second, Mtexel/s and bw_fraction for `bytes` read + written per run over `texels`
// in `seconds` per run (what time_runs returned).
void set_throughput(benchmark::State& state, double bytes, double texels, double seconds);

// Receivers of a camera-like view (screen(): 1920x1080) of a map x map shadow map, in screen
// order (bench_pipeline.cpp): u, v, d and footprints f in level-0 texels.
void coherent_receivers(int map, std::vector<float>& u, std::vector<float>& v, std::vector<float>& d,
                        std::vector<float>& f);
// bench_pipeline.cpp's ESM frame: a map x map white-noise depth map (random_floats seed 9) and
// screen() receivers, coherent (coherent_receivers) or random (u, v, d uniform, f in [1, 8],
// seeds 10-13).
struct EsmFrame {
  std::vector<float> depth, u, v, d, f;
};
EsmFrame esm_frame(int map, bool coherent);
// A frame's receivers as device buffers: an image of `row` receivers per row (0: points), with
// the footprints f when `footprints`.
DeviceReceivers receivers_on_device(const EsmFrame& fr, int row, bool footprints);
#ifdef SF_BENCH_HAVE_SCENE
// A built-in scene (scene library, docs/scenes.md) as a frame: its light's map x map depth map
// and its camera's width x height receivers (u, v, d, f), rendered once per argument set and
// kept for the run (bench_scene_frame.cpp).
const EsmFrame& scene_frame(const std::string& scene, int map, int width, int height);
#endif
// Deterministic uniform random floats in [lo, hi].
std::vector<float> random_floats(size_t n, unsigned seed, float lo = 0.0f, float hi = 1.0f);
// A device buffer holding `host`, and an uninitialised one of `bytes`.
cl::Buffer to_device(const std::vector<float>& host);
cl::Buffer device_buffer(size_t bytes);
// The table a footprint lookup reads, built (and waited for) outside the timing from a float32
// basis of `shape`: mips -> the mean chain, sat -> the float-float table, bilinear -> none.
LookupBuffers lookup_tables(Lookup kind, const cl::Buffer& basis, const ImageShape& shape, const cl::Buffer& footprint);

// A mip pyramid (Reduce::Mean of `shape.channels` planes, or the Max / Min depth pyramids) of
// random float32 values, timed from its first to its last launch; bytes: level 0 read + every
// level written (bench_pyramid.cpp: mean, z-max; bench_coverage.cpp: z-min).
void time_chain(benchmark::State& state, Reduce op, const ImageShape& shape, unsigned seed);

// Smoke mode (SF_BENCH_SMOKE=1, what `make bench-smoke` runs in CI): every benchmark family and
// variant (method, storage, lookup, vector width, radius, baseline) is registered as usual, but
// at a small problem size, so that one that breaks (an error, a failed agreement check) shows in
// about a minute. Its figures mean nothing. The sizes go through the helpers below, never through
// a second copy of a registration.
bool smoke();
// The largest map side in smoke mode: 512, the smallest map of the size lists.
constexpr int kSmokeMap = 512;
// A map side: n, or at most kSmokeMap in smoke mode.
int smoke_size(int n);
// A size list to register: the list, or in smoke mode its smallest entry alone (at most
// kSmokeMap). A family whose sizes are split over several registrations registers its larger
// ones only when !smoke() (their smallest size runs in the first).
std::vector<int64_t> sizes(const std::vector<int64_t>& list);
// Another fixed dimension (a view count, a query count): n, or n / by in smoke mode.
int smoke_scaled(int n, int by);

// The receivers' screen of the camera-like benchmarks: 1920x1080, or 320x180 in smoke mode.
struct Screen {
  int width, height;
  size_t count() const { return size_t(width) * height; }
  std::string name() const { return std::to_string(width) + "x" + std::to_string(height); }
};
Screen screen();

// Repetitions per benchmark: 5, or SF_BENCH_REPETITIONS.
int repetitions();
// Every benchmark uses these settings: manual time in ms; mean, median, stddev, cv and min over
// the repetitions.
benchmark::internal::Benchmark* configure(benchmark::internal::Benchmark* b);

// Registration, one per file, called by main in this order.
void register_copy();
void register_transform();
void register_blur();
// cv::GaussianBlur at one size and radius, registered by register_blur right after ours, so
// that both run under the same load (only with SF_HAVE_OPENCV).
void register_opencv_blur(int size, int radius);
void register_reconstruct();
void register_pipeline();
void register_layered();  // bench_layered.cpp: four layers of (S/2)^2 against one S^2 map
void register_pyramid();  // bench_pyramid.cpp: mips, SAT, footprint lookups
// bench_coverage.cpp: each method x lookup x map size, and the scalar reference kernels.
void register_coverage();
// bench_classify.cpp: the classified ESM frame against the unclassified one.
void register_classify();
// cv::pyrDown (one level) at one size (only with SF_HAVE_OPENCV).
void register_opencv_pyrdown();

// Measures the copy bandwidth: the best median of clEnqueueCopyBuffer and two copy kernels.
double measure_copy_bandwidth();

}  // namespace sf::bench

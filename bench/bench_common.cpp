#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"
#include "bench_common.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <random>
#include <string>

namespace sf::bench {
namespace {
double g_reference_bandwidth = 0.0;
// Defaults 5 repetitions of at least 0.2 s; SF_BENCH_REPETITIONS / SF_BENCH_MIN_TIME override them
// (`make bench` uses fewer to stay within minutes on a loaded 2-core machine). Read from the
// environment, not from flags: some suites register statically, before main sees argv.
double env_number(const char* name, double fallback, double lo) {
  const char* v = std::getenv(name);
  if (!v || !*v) return fallback;
  char* end = nullptr;
  const double x = std::strtod(v, &end);
  return end && *end == 0 && x >= lo ? x : fallback;
}
double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
}  // namespace

std::shared_ptr<Runtime> runtime_ptr() {
  static std::shared_ptr<Runtime> rt = Runtime::create();
  return rt;
}
Runtime& runtime() { return *runtime_ptr(); }

double reference_bandwidth() { return g_reference_bandwidth; }
void set_reference_bandwidth(double bytes_per_second) { g_reference_bandwidth = bytes_per_second; }

double time_runs(benchmark::State& state, const TimedRun& run, int warmups, const std::function<void()>& warmed) {
  for (int i = 0; i < warmups; ++i) run();
  if (warmed) warmed();
  double total = 0.0;
  for (auto _ : state) {
    const double s = run();
    state.SetIterationTime(s);
    total += s;
  }
  return state.iterations() > 0 ? total / state.iterations() : 0.0;
}

double median_seconds(const TimedRun& run, int runs, int warmups) {
  for (int i = 0; i < warmups; ++i) run();
  std::vector<double> t(runs);
  for (double& s : t) s = run();
  std::nth_element(t.begin(), t.begin() + runs / 2, t.end());
  return t[runs / 2];
}

double wall_seconds(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void set_throughput(benchmark::State& state, double bytes, double texels, double seconds) {
  state.SetBytesProcessed(static_cast<int64_t>(bytes) * state.iterations());
  if (seconds <= 0) return;
  state.counters["Mtexel/s"] = texels * 1e-6 / seconds;
  if (reference_bandwidth() > 0) state.counters["bw_fraction"] = bytes / seconds / reference_bandwidth();
}

std::vector<float> random_floats(size_t n, unsigned seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = dist(rng);
  return v;
}

cl::Buffer to_device(const std::vector<float>& host) {
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, host.size() * sizeof(float),
                    const_cast<float*>(host.data()));
}

cl::Buffer device_buffer(size_t bytes) { return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, bytes); }

LookupBuffers lookup_tables(Lookup kind, const cl::Buffer& basis, const ImageShape& shape,
                            const cl::Buffer& footprint) {
  LookupBuffers lk;
  lk.kind = kind;
  lk.footprint = footprint;
  if (kind == Lookup::Mips) {
    lk.chain = device_buffer(mip_layout(shape.width, shape.height, shape.channels).chain_values * sizeof(float));
    enqueue_pyramid(runtime(), Reduce::Mean, Storage::F32, {}, shape, basis, lk.chain).wait();
  } else if (kind == Lookup::Sat) {
    const SatLayout L = sat_layout(shape);
    lk.sat = device_buffer(L.table_floats * sizeof(float));
    cl::Buffer bands = device_buffer(L.band_floats * sizeof(float));
    enqueue_sat(runtime(), Storage::F32, {}, {}, shape, basis, lk.sat, bands).wait();
  }
  return lk;
}

void time_chain(benchmark::State& state, Reduce op, const ImageShape& shape, unsigned seed) {
  const size_t values = shape.plane_texels() * shape.channels;
  const size_t chain_values = mip_layout(shape.width, shape.height, shape.channels).chain_values;
  cl::Buffer src = to_device(random_floats(values, seed));
  cl::Buffer chain = device_buffer(std::max<size_t>(chain_values, 1) * sizeof(float));
  const double s = time_runs(state, [&] {
    cl::Event first;
    const cl::Event last = enqueue_pyramid(runtime(), op, Storage::F32, {}, shape, src, chain, &first);
    last.wait();
    return event_seconds(first, last);
  });
  set_throughput(state, 4.0 * double(values + chain_values), double(values), s);
}

bool smoke() {
  static const bool on = [] {
    const char* v = std::getenv("SF_BENCH_SMOKE");
    return v && std::string(v) == "1";
  }();
  return on;
}

int smoke_size(int n) { return smoke() ? std::min(n, kSmokeMap) : n; }

std::vector<int64_t> sizes(const std::vector<int64_t>& list) {
  if (!smoke()) return list;
  return {smoke_size(int(*std::min_element(list.begin(), list.end())))};
}

int smoke_scaled(int n, int by) { return smoke() ? n / by : n; }

Screen screen() { return {smoke_scaled(1920, 6), smoke_scaled(1080, 6)}; }

int repetitions() { return int(env_number("SF_BENCH_REPETITIONS", 5, 1)); }

benchmark::internal::Benchmark* configure(benchmark::internal::Benchmark* b) {
  return b->UseManualTime()
      ->Unit(benchmark::kMillisecond)
      ->MinTime(env_number("SF_BENCH_MIN_TIME", 0.2, 0))
      ->Repetitions(repetitions())
      ->ComputeStatistics("min", min_of)  // shared machines: the least disturbed repetition
      ->ReportAggregatesOnly(true);
}

}  // namespace sf::bench

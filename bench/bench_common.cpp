#include "bench_common.hpp"

#include <algorithm>
#include <chrono>
#include <random>

namespace sf::bench {
namespace {
double g_reference_bandwidth = 0.0;
constexpr int kRepetitions = 5;
constexpr double kMinSecondsPerRepetition = 0.2;
double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
}  // namespace

std::shared_ptr<Runtime> runtime_ptr() {
  static std::shared_ptr<Runtime> rt = Runtime::create();
  return rt;
}
Runtime& runtime() { return *runtime_ptr(); }

double reference_bandwidth() { return g_reference_bandwidth; }
void set_reference_bandwidth(double bytes_per_second) { g_reference_bandwidth = bytes_per_second; }

double time_runs(benchmark::State& state, const TimedRun& run, int warmups) {
  for (int i = 0; i < warmups; ++i) run();
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
  if (reference_bandwidth() > 0)
    state.counters["bw_fraction"] = bytes / seconds / reference_bandwidth();
}

std::vector<float> random_floats(size_t n, unsigned seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = dist(rng);
  return v;
}

cl::Buffer to_device(const std::vector<float>& host) {
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                    host.size() * sizeof(float), const_cast<float*>(host.data()));
}

cl::Buffer device_buffer(size_t bytes) {
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, bytes);
}

benchmark::internal::Benchmark* configure(benchmark::internal::Benchmark* b) {
  return b->UseManualTime()
      ->Unit(benchmark::kMillisecond)
      ->MinTime(kMinSecondsPerRepetition)
      ->Repetitions(kRepetitions)
      ->ComputeStatistics("min", min_of)  // shared machines: the least disturbed repetition
      ->ReportAggregatesOnly(true);
}

}  // namespace sf::bench

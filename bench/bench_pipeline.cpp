// 5. The full ESM pipeline through sf::Pipeline: 2048x2048 depth, c = 80, blur R = 3, then
// 1920x1080 receivers (smoke mode: smoke_size(2048) and screen()), bilinear (lookup 0) or trilinear mips (lookup 1).
// Receivers: random (rx 0: u, v, d white noise, footprints uniform in [1, 8]) or coherent (rx 1: a camera-like sweep of
// the map in screen order, as a rendered view gives them: neighbouring pixels read neighbouring texels, footprints from
// the map's screen derivatives, 0.6 .. 5 texels). Device time = every stage's profiling events; per-stage times as
// counters. Bytes: 8 per map texel (transform) + 16 (blur) + 16 per receiver (+ 4 with footprints).
// 6. The host convenience sf::filter (frame_filter.hpp) on host arrays: an n x n map and one
// receiver per texel, vsm with blur R = 2, uploaded, filtered and downloaded on the warm runtime;
// host wall time. The C++ side of the Python binding's call overhead (bench/python_layers.py
// times shadowfilter.filter on the same frame against it).
#include <algorithm>
#include <cmath>

#include "bench_common.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::bench {

// A floor seen in perspective: screen row y maps to map row v = v0 + (y / H)^2 span (far rows
// squeezed), columns spread linearly; depth varies smoothly around the map's values.
void coherent_receivers(int map, std::vector<float>& u, std::vector<float>& v, std::vector<float>& d,
                        std::vector<float>& f) {
  const int w = screen().width, h = screen().height;
  const size_t count = screen().count();
  u.resize(count), v.resize(count), d.resize(count), f.resize(count);
  for (int y = 0; y < h; ++y) {
    const double t = (y + 0.5) / h;
    const double vv = 0.05 + 0.9 * t * t, dv_dy = 0.9 * 2 * t / h;
    const double spread = 0.3 + 0.6 * t;  // near rows (t = 1) cover more of the map's width
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const double s = (x + 0.5) / w;
      u[i] = float(0.5 + spread * (s - 0.5));
      v[i] = float(vv);
      d[i] = float(0.5 + 0.3 * std::sin(6.0 * s) * t);
      f[i] = float(std::max(spread / w, dv_dy) * map);
    }
  }
}

EsmFrame esm_frame(int map, bool coherent) {
  EsmFrame fr;
  fr.depth = random_floats(size_t(map) * map, 9);
  if (coherent) {
    coherent_receivers(map, fr.u, fr.v, fr.d, fr.f);
  } else {
    const size_t count = screen().count();
    fr.u = random_floats(count, 10);
    fr.v = random_floats(count, 11);
    fr.d = random_floats(count, 12);
    fr.f = random_floats(count, 13, 1.0f, 8.0f);
  }
  return fr;
}

DeviceReceivers receivers_on_device(const EsmFrame& fr, int row, bool footprints) {
  DeviceReceivers rx;
  rx.count = fr.u.size();
  rx.row = row;
  rx.u = to_device(fr.u), rx.v = to_device(fr.v), rx.d = to_device(fr.d);
  if (footprints) rx.f = to_device(fr.f);
  return rx;
}

namespace {

void BM_EsmPipeline(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  const bool mips = state.range(2) == 1, coherent = state.range(3) == 1;
  const size_t texels = size_t(n) * n, count = screen().count();
  FilterOptions opt;
  opt.blur.radius = radius;
  if (mips) opt.lookup.kind = Lookup::Mips;
  Pipeline pipe(runtime_ptr(), opt, n, n);
  cl::Buffer depth = to_device(random_floats(texels, 9));
  DeviceReceivers rx;
  rx.count = count;
  if (coherent) {
    std::vector<float> u, v, d, f;
    coherent_receivers(n, u, v, d, f);
    rx.u = to_device(u), rx.v = to_device(v), rx.d = to_device(d);
    if (mips) rx.f = to_device(f);
  } else {
    rx.u = to_device(random_floats(count, 10));
    rx.v = to_device(random_floats(count, 11));
    rx.d = to_device(random_floats(count, 12));
    if (mips) rx.f = to_device(random_floats(count, 13, 1.0f, 8.0f));
  }
  cl::Buffer vis = device_buffer(count * sizeof(float));
  StageTimes sum;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        EventList filtered{pipe.prefilter(depth)};
        pipe.reconstruct(rx, vis, &filtered).wait();
        const StageTimes t = pipe.times();
        sum.transform += t.transform;
        sum.blur += t.blur;
        sum.pyramid += t.pyramid;
        sum.reconstruct += t.reconstruct;
        ++runs;
        return t.transform + t.blur + t.pyramid + t.reconstruct;
      },
      2, [&] { sum = {}, runs = 0; });
  state.counters["transform_ms"] = 1e3 * sum.transform / runs;
  state.counters["blur_ms"] = 1e3 * sum.blur / runs;
  state.counters["mips_ms"] = 1e3 * sum.pyramid / runs;
  state.counters["reconstruct_ms"] = 1e3 * sum.reconstruct / runs;
  if (s > 0) state.counters["fps"] = 1.0 / s;
  set_throughput(state, 24.0 * texels + (mips ? 20.0 : 16.0) * count, texels, s);
}

void BM_HostFilter(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  HostImage depth(n, n, 1);
  depth.data = random_floats(size_t(n) * n, 9, 0.2f, 0.9f);
  Receivers rx;
  rx.width = rx.height = n;
  rx.grid = true;
  rx.d = random_floats(size_t(n) * n, 10, 0.2f, 0.9f);
  FilterOptions opt;
  opt.method = "vsm";
  opt.blur.radius = 2;
  const auto rt = runtime_ptr();
  const double s = time_runs(state, [&] {
    return wall_seconds([&] { benchmark::DoNotOptimize(filter(rt, opt, depth, rx).visibility.data.data()); });
  });
  if (s > 0) state.counters["fps"] = 1.0 / s;
}

}  // namespace

void register_pipeline() {
  const int64_t map = smoke_size(2048);
  configure(benchmark::RegisterBenchmark(("esm_pipeline/points_" + screen().name()).c_str(), BM_EsmPipeline))
      ->ArgNames({"size", "R", "lookup", "rx"})
      ->Args({map, 3, 0, 0})
      ->Args({map, 3, 1, 0})
      ->Args({map, 3, 1, 1});
  configure(benchmark::RegisterBenchmark("host_filter/grid_vsm", BM_HostFilter))
      ->ArgNames({"size"})
      ->Arg(smoke_size(512));
}

}  // namespace sf::bench

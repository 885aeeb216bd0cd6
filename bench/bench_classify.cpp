// The ESM default frame with its z-max classification (esm_classify.cl) against the same frame
// unclassified, interleaved in one run (issue: "classification as cheap as the lookup").
//
// esm_classify/frame: esm with its defaults (c = 120, classification zmax), blur R = 3 (make run's),
// the bilinear lookup (lookup 0, the default) or trilinear mips (lookup 1), a size x size map and
// screen() receivers (1920x1080; smoke mode: 512 and 320x180). Scenes:
//   0  white noise (random_floats seed 9) and random receivers (u, v, d uniform, f in [1, 8]):
//      nearly every receiver is flagged, the classification's worst case;
//   1  the same map and bench_pipeline.cpp's coherent camera sweep;
//   2  the backyard scene (scene library: its light's depth map and its camera's receivers,
//      u v d f), a realistic frame with a few percent flagged.
// The receivers are an image (DeviceReceivers::row = its width), as the CLI passes them: a flagged
// receiver's plane comes from its neighbours. Each iteration runs the classified pipeline, then the unclassified one on
// the same data; the manual time is the classified frame's device time (every stage's profiling events). Counters:
// reconstruct_ms (the lookup), zmax_ms (max filter and z-max pyramid), classify_ms (flags and the
// 2x2 fall-back), classify_over_reconstruct = (zmax + classify) / reconstruct, the target of
// at most 1 on realistic scenes and 2 where everything is flagged; frame_over_unclassified, the
// default frame against the plain one; flagged_pct.
#include <algorithm>
#include <cmath>

#include "bench_common.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::bench {
namespace {

void BM_ClassifiedFrame(benchmark::State& state) {
  const int n = int(state.range(0)), scene = int(state.range(1));
  const bool mips = state.range(2) == 1;
  EsmFrame fr;
#ifdef SF_BENCH_HAVE_SCENE
  if (scene == 2) fr = scene_frame("backyard", n, screen().width, screen().height);
#endif
  if (scene != 2) fr = esm_frame(n, scene == 1);
  FilterOptions opt;  // esm, c = 120, classification Auto = zmax
  opt.blur.radius = 3;
  if (mips) opt.lookup.kind = Lookup::Mips;
  FilterOptions plain = opt;
  plain.esm_classify.mode = EsmClassify::None;
  Pipeline classified(runtime_ptr(), opt, n, n), unclassified(runtime_ptr(), plain, n, n);
  cl::Buffer depth = to_device(fr.depth);
  // An image of receivers, as the CLI reads them: planes from neighbours.
  const DeviceReceivers rx = receivers_on_device(fr, screen().width, mips);
  cl::Buffer vis = device_buffer(rx.count * sizeof(float));
  const auto frame = [&](Pipeline& p) {
    const EventList filtered{p.prefilter(depth)};
    p.reconstruct(rx, vis, &filtered).wait();
    return p.times();
  };
  StageTimes sum;
  double plain_s = 0;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        const StageTimes t = frame(classified);
        plain_s += frame(unclassified).total();
        sum.reconstruct += t.reconstruct, sum.zmax += t.zmax, sum.classify += t.classify;
        ++runs;
        return t.total();
      },
      2, [&] { sum = {}, plain_s = 0, runs = 0; });
  std::vector<uint8_t> flags(rx.count);
  runtime().queue().enqueueReadBuffer(classified.flags(), CL_TRUE, 0, rx.count, flags.data());
  size_t inside = 0;
  for (size_t i = 0; i < rx.count; ++i) inside += std::isfinite(fr.u[i]) && std::isfinite(fr.d[i]);
  const size_t flagged = size_t(std::count(flags.begin(), flags.end(), uint8_t(1)));
  state.counters["reconstruct_ms"] = 1e3 * sum.reconstruct / runs;
  state.counters["zmax_ms"] = 1e3 * sum.zmax / runs;
  state.counters["classify_ms"] = 1e3 * sum.classify / runs;
  state.counters["classify_over_reconstruct"] = (sum.zmax + sum.classify) / sum.reconstruct;
  state.counters["frame_over_unclassified"] = s * runs / plain_s;
  state.counters["flagged_pct"] = 100.0 * flagged / std::max<size_t>(inside, 1);
}

// The default frame on a new Pipeline: each iteration builds a new Pipeline and uploads the
// frame into new buffers, runs the frame, then runs it again on that warm pipeline. Manual time:
// the fresh frame's device time; counters fresh_over_warm, each stage's fresh and warm ms and
// resident_ms (the fills that fault in the new pipeline's buffers, resident.hpp). In one process
// the allocator hands freed pages back, and the programs are built once: a new process's first
// frame costs more (scripts/one_shot.sh, docs/batch.md).
void BM_FreshFrame(benchmark::State& state) {
  const int n = int(state.range(0));
  EsmFrame fr;
#ifdef SF_BENCH_HAVE_SCENE
  fr = scene_frame("backyard", n, screen().width, screen().height);
#else
  fr = esm_frame(n, true);
#endif
  FilterOptions opt;
  opt.blur.radius = 3;
  StageTimes fresh, warm;
  int runs = 0;
  time_runs(
      state,
      [&] {
        Pipeline pipe(runtime_ptr(), opt, n, n);
        const cl::Buffer depth = to_device(fr.depth);
        const DeviceReceivers rx = receivers_on_device(fr, screen().width, false);
        const cl::Buffer vis = device_buffer(rx.count * sizeof(float));
        const auto frame = [&] {
          const EventList filtered{pipe.prefilter(depth)};
          pipe.reconstruct(rx, vis, &filtered).wait();
          return pipe.times();
        };
        const StageTimes t = frame();
        fresh += t, warm += frame();
        ++runs;
        return t.total();
      },
      1, [&] { fresh = warm = {}, runs = 0; });
  state.counters["fresh_over_warm"] = fresh.total() / warm.total();
  const auto stage = [&](const char* name, double StageTimes::*m) {
    state.counters[std::string(name) + "_fresh_ms"] = 1e3 * fresh.*m / runs;
    state.counters[std::string(name) + "_warm_ms"] = 1e3 * warm.*m / runs;
  };
  stage("transform", &StageTimes::transform);
  stage("blur", &StageTimes::blur);
  stage("zmax", &StageTimes::zmax);
  stage("reconstruct", &StageTimes::reconstruct);
  stage("classify", &StageTimes::classify);
  state.counters["resident_ms"] = 1e3 * fresh.resident / runs;
}

}  // namespace

void register_classify() {
  auto* b = configure(benchmark::RegisterBenchmark("esm_classify/frame", BM_ClassifiedFrame))
                // scene: 0 noise + random rx, 1 noise + coherent rx, 2 backyard; lookup: 0 bilinear, 1 mips
                ->ArgNames({"size", "scene", "lookup"});
  for (int64_t lookup : {0, 1}) {
    b->Args({smoke_size(2048), 0, lookup});
    b->Args({smoke_size(2048), 1, lookup});
  }
  configure(benchmark::RegisterBenchmark("esm_classify/fresh_frame", BM_FreshFrame))
      ->ArgName("size")
      ->Arg(smoke_size(2048));
#ifdef SF_BENCH_HAVE_SCENE
  b->Args({smoke_size(2048), 2, 0});
  b->Args({smoke_size(2048), 2, 1});
#else
  (void)b;
#endif
}

}  // namespace sf::bench

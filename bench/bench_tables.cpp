// The seeds' performance tables in their own shapes (docs/performance.md, written from this
// file's JSON by scripts/performance_tables.py; `make performance`). Every entry is a whole
// filtered frame of the backyard scene (scene library: its light's depth map and its camera's
// receivers, passed as an image): the device time of every stage from the depth map to the
// visibility (transform, blur, mip chain, z-max pyramid and classification, reconstruction),
// fps = 1 / that time. The seed's frames also rasterised and shaded the scene; ours start from
// the rendered depth map, so only the filtering is compared.
//   table6_1/csm       seed 000 Table 6.1: csm at M = 4, 8, 16 x map 256..2048 x convolution
//                      C = 1 (none), 3, 7 (a Gaussian of radius (C - 1) / 2), trilinear mips,
//                      1024x768 receivers. table6_1/pcf: the 2x2 PCF on the raw depth, the
//                      seed's hardware-PCF row (no convolution, bilinear).
//   table7_1/<method>  Table 7.1: esm_t (esm, threshold classification), esm_z (esm, z-max),
//                      vsm and csm (M = 4) x map 512..2048 x C = 1, 3, 7, trilinear mips,
//                      1920x1080 receivers.
//   table7_3/<method>  Table 7.3: esm_z and esm_t x map 128..1024 x C = 1, 3, 5, 800x800
//                      receivers; the counter classify_ms is the classification alone (z-max
//                      pyramid, flags and fall-back), the table's subject.
//   table8_1/cssm_<lookup>  Table 8.1: cssm (M = 4, the seed's order) with mips or the SAT x map
//                      128..1024 x lights 1, 10, 20, 40, 1024x768 receivers. Each light is its
//                      own map, prefiltered and reconstructed in turn by one SoftFilter (the
//                      basis of one light resident at a time: the seed's missing entries are
//                      lights whose bases did not fit). The maps are copies of backyard's and
//                      every light reads the same receivers; the weighted sum of the lights'
//                      visibilities (one add per receiver and light) is not included.
// Smoke mode: the smallest map of each list and the receivers' screen divided by 6.
#include <algorithm>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::bench {
namespace {

struct TableScreen {
  int width, height;
};
TableScreen table_screen(int width, int height) { return {smoke_scaled(width, 6), smoke_scaled(height, 6)}; }

// Args: map size, convolution size C (odd), and for csm the order M when `csm_order` is 0.
void BM_Frame(benchmark::State& state, FilterOptions opt, TableScreen scr, int csm_order) {
  const int n = int(state.range(0)), c = int(state.range(1));
  opt.blur.radius = (c - 1) / 2;
  if (opt.method == "csm") opt.csm.order = csm_order > 0 ? csm_order : int(state.range(2));
  const EsmFrame& fr = scene_frame("backyard", n, scr.width, scr.height);
  Pipeline pipe(runtime_ptr(), opt, n, n);
  const cl::Buffer depth = to_device(fr.depth);
  const DeviceReceivers rx = receivers_on_device(fr, scr.width, opt.lookup.kind != Lookup::Bilinear);
  const cl::Buffer vis = device_buffer(rx.count * sizeof(float));
  StageTimes sum;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        const EventList filtered{pipe.prefilter(depth)};
        pipe.reconstruct(rx, vis, &filtered).wait();
        const StageTimes t = pipe.times();
        sum += t;
        ++runs;
        return t.total();
      },
      2, [&] { sum = {}, runs = 0; });
  if (s > 0) state.counters["fps"] = 1.0 / s;
  state.counters["transform_ms"] = 1e3 * sum.transform / runs;
  state.counters["blur_ms"] = 1e3 * sum.blur / runs;
  state.counters["mips_ms"] = 1e3 * sum.pyramid / runs;
  state.counters["reconstruct_ms"] = 1e3 * sum.reconstruct / runs;
  state.counters["classify_ms"] = 1e3 * (sum.zmax + sum.classify) / runs;
  state.counters["device_MB"] = 1e-6 * double(pipe.device_bytes());
}

// Args: map size, lights.
void BM_SoftLights(benchmark::State& state, Lookup lookup) {
  const int n = int(state.range(0)), lights = int(state.range(1));
  const TableScreen scr = table_screen(1024, 768);
  const EsmFrame& fr = scene_frame("backyard", n, scr.width, scr.height);
  SoftOptions opt;
  opt.method = SoftMethod::Cssm;
  opt.cssm.order = 4;
  opt.cssm.lookup = lookup;
  SoftFilter filter(runtime_ptr(), opt, n, n);
  const std::vector<cl::Buffer> maps(size_t(lights), to_device(fr.depth));
  const DeviceReceivers rx = receivers_on_device(fr, scr.width, true);
  const cl::Buffer vis = device_buffer(rx.count * sizeof(float));
  // The warm-up is one light (it builds and compiles every kernel); a 40-light frame of the SAT
  // at 1024^2 takes seconds, so the frame itself runs only timed.
  filter.prefilter(maps[0]).wait();
  filter.reconstruct(rx, vis).wait();
  double prepare = 0, reconstruct = 0;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        double frame = 0;
        for (const cl::Buffer& map : maps) {
          const EventList filtered{filter.prefilter(map)};
          filter.reconstruct(rx, vis, &filtered).wait();
          const StageTimes t = filter.times();
          prepare += t.transform + t.pyramid + t.sat;
          reconstruct += t.reconstruct;
          frame += t.total();
        }
        ++runs;
        return frame;
      },
      0);
  if (s > 0) state.counters["fps"] = 1.0 / s;
  state.counters["prepare_ms"] = 1e3 * prepare / runs;
  state.counters["reconstruct_ms"] = 1e3 * reconstruct / runs;
  state.counters["device_MB"] = 1e-6 * double(filter.device_bytes());
}

FilterOptions frame_options(const std::string& method, EsmClassify classify = EsmClassify::Auto) {
  FilterOptions opt;
  opt.method = method;
  opt.lookup.kind = Lookup::Mips;
  opt.esm_classify.mode = classify;
  return opt;
}

const bool registered = [] {
  FilterOptions pcf;
  pcf.method = "pcf";
  configure(benchmark::RegisterBenchmark("table6_1/pcf", BM_Frame, pcf, table_screen(1024, 768), 0))
      ->ArgNames({"size", "C"})
      ->ArgsProduct({sizes({256, 512, 1024, 2048}), {1}});
  configure(benchmark::RegisterBenchmark("table6_1/csm", BM_Frame, frame_options("csm"), table_screen(1024, 768), 0))
      ->ArgNames({"size", "C", "M"})
      ->ArgsProduct({sizes({256, 512, 1024, 2048}), {1, 3, 7}, {4, 8, 16}});
  const std::vector<std::pair<std::string, FilterOptions>> methods71 = {
      {"esm_t", frame_options("esm", EsmClassify::Threshold)},
      {"esm_z", frame_options("esm", EsmClassify::ZMax)},
      {"vsm", frame_options("vsm")},
      {"csm", frame_options("csm")}};
  for (const auto& [name, opt] : methods71)
    configure(benchmark::RegisterBenchmark(("table7_1/" + name).c_str(), BM_Frame, opt, table_screen(1920, 1080), 4))
        ->ArgNames({"size", "C"})
        ->ArgsProduct({sizes({512, 1024, 2048}), {1, 3, 7}});
  for (const auto& [name, mode] : {std::pair{"esm_z", EsmClassify::ZMax}, std::pair{"esm_t", EsmClassify::Threshold}})
    configure(benchmark::RegisterBenchmark((std::string("table7_3/") + name).c_str(), BM_Frame,
                                           frame_options("esm", mode), table_screen(800, 800), 0))
        ->ArgNames({"size", "C"})
        ->ArgsProduct({sizes({128, 256, 512, 1024}), {1, 3, 5}});
  for (const auto& [name, lookup] : {std::pair{"mips", Lookup::Mips}, std::pair{"sat", Lookup::Sat}})
    configure(benchmark::RegisterBenchmark((std::string("table8_1/cssm_") + name).c_str(), BM_SoftLights, lookup))
        ->ArgNames({"size", "lights"})
        ->ArgsProduct({sizes({128, 256, 512, 1024}), {1, 10, 20, 40}})
        ->Repetitions(1);  // a 40-light SAT frame at 1024^2 takes about 40 s on PoCL
  return true;
}();

}  // namespace
}  // namespace sf::bench

// 6. Every method's kernels: the basis transform of every basis method x storage it
// accepts (csm at M = 4, 8, 16; the case list of tests/support/method_cases.hpp, shared with the
// method tests) at 2048^2 and every transform vector width (1 = one texel per work-item,
// 4/8/16 = sf_transformv), and at 512^2 and 4096^2 with the default width 16 (csm at M = 4 only
// at 4096: M = 16 in f32 is 2 GiB of basis); the reconstruction of each method (sm / pcf: the
// raw-depth test) at 1920x1080 random receivers on 512, 2048 and 4096 maps; and cv::pyrDown
// beside our mean pyramid (bench_pyramid.cpp) as a baseline. Device time from profiling events;
// bytes are what the kernel must move at least (transform: 4 bytes read + the basis bytes written
// per texel), so bw_fraction is the transform's throughput as a fraction of the copy bandwidth.
// Smoke mode: every transform vector width at smoke_size(2048) = 512 (the 512 and 4096 rows of
// width 16 left out: the first is the same run), the reconstructions at 512 with screen()'s
// receivers (the 4096 family left out).
// Registered statically (no edit to bench_main.cpp): configure() and the copy bandwidth are
// read when the benchmarks run, after main has measured it.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "method_cases.hpp"
#include "shadowfilter/methods.hpp"

#ifdef SF_HAVE_OPENCV
#include <opencv2/imgproc.hpp>
#endif

namespace sf::bench {
namespace {

// Args: map size, transform vector width.
void BM_Transform(benchmark::State& state, FilterOptions opt) {
  const int n = static_cast<int>(state.range(0));
  opt.schedule.transform_vector_width = static_cast<int>(state.range(1));
  const size_t texels = size_t(n) * n;
  const MethodDesc& m = *opt.method;
  const size_t out_bytes = basis_bytes_per_texel(m, opt) * texels;
  cl::Buffer depth = to_device(random_floats(texels, 2));
  cl::Buffer basis = device_buffer(out_bytes);
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_transform(runtime(), m, opt, n, n, depth, basis);
    e.wait();
    return event_seconds(e);
  });
  state.counters["channels"] = m.channels(opt);
  state.counters["basis_B/texel"] = double(basis_bytes_per_texel(m, opt));
  set_throughput(state, double(sizeof(float) * texels + out_bytes), double(texels), s);
}

// Arg: map size.
void BM_Reconstruct(benchmark::State& state, std::string method) {
  const int n = static_cast<int>(state.range(0));
  const size_t texels = size_t(n) * n, count = screen().count();
  const FilterOptions opt = MethodCase{method, Storage::F32, 8}.options();
  const MethodDesc& m = *sf::method(method);
  cl::Buffer depth = to_device(random_floats(texels, 3));
  cl::Buffer u = to_device(random_floats(count, 4)), v = to_device(random_floats(count, 5)),
             d = to_device(random_floats(count, 6));
  cl::Buffer vis = device_buffer(count * sizeof(float));
  cl::Buffer basis;
  size_t basis_bytes = 0;
  if (!m.raw_depth) {
    basis_bytes = basis_bytes_per_texel(m, opt) * texels;
    basis = device_buffer(basis_bytes);
    enqueue_transform(runtime(), m, opt, n, n, depth, basis).wait();
  }
  const double s = time_runs(state, [&] {
    cl::Event e =
        m.raw_depth
            ? enqueue_pcf_points(runtime(), opt, n, n, count, 0, depth, u, v, d, cl::Buffer(), cl::Buffer(), vis)
            : enqueue_reconstruct_points(runtime(), m, opt, n, n, count, 0, basis, nullptr, u, v, d, vis);
    e.wait();
    return event_seconds(e);
  });
  // Per receiver: u, v, d read, v written, and 4 texels of every basis plane (the bilinear taps).
  const double per_rx = 16.0 + 4.0 * (m.raw_depth ? 4.0 : double(basis_bytes) / texels);
  set_throughput(state, per_rx * count, double(count), s);
}

#ifdef SF_HAVE_OPENCV
// cv::pyrDown is a 5x5 Gaussian then decimation (not our 2x2 mean), the closest OpenCV level
// builder; a full chain down to 1x1, host wall time on both cores.
void BM_OpenCvPyrDownChain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  cv::setNumThreads(2);
  const auto values = random_floats(size_t(n) * n, 7);
  const cv::Mat src(n, n, CV_32F, const_cast<float*>(values.data()));
  std::vector<cv::Mat> levels;
  const double s =
      time_runs(state, [&] { return wall_seconds([&] { cv::buildPyramid(src, levels, int(std::log2(n))); }); });
  set_throughput(state, 4.0 * n * n * (1.0 + 1.0 / 3.0), double(n) * n, s);
}
#endif

const bool registered = [] {
  for (const MethodCase& mc : method_storage_cases({4, 8, 16})) {
    const std::string name = "transform/" + mc.method.name() + "/" + storage_name(mc.storage) +
                             (mc.method == "csm" ? "/M" + std::to_string(mc.csm_order) : "");
    auto* b = configure(benchmark::RegisterBenchmark(name.c_str(), BM_Transform, mc.options()))
                  ->ArgNames({"size", "vec"})
                  ->ArgsProduct({{smoke_size(2048)}, {1, 4, 8, 16}});
    if (smoke()) continue;
    b->Args({512, 16});
    if (mc.method != "csm" || mc.csm_order == 4) b->Args({4096, 16});
  }
  // 4096: at most 2 repetitions (csm takes about a second a run on the loaded 2-core machine).
  for (const auto& m : methods())
    for (bool large : {false, true}) {
      if (large && smoke()) continue;
      auto* b = configure(benchmark::RegisterBenchmark(("reconstruct/" + m.name + "/points_" + screen().name()).c_str(),
                                                       BM_Reconstruct, m.name))
                    ->ArgName("size");
      if (large)
        b->Repetitions(std::min(2, repetitions()))->Arg(4096);
      else
        b->ArgsProduct({sizes({512, 2048})});
    }
#ifdef SF_HAVE_OPENCV
  configure(benchmark::RegisterBenchmark("mips/opencv_buildPyramid", BM_OpenCvPyrDownChain))
      ->ArgName("size")
      ->ArgsProduct({sizes({512, 2048, 4096})});
#endif
  return true;
}();

}  // namespace
}  // namespace sf::bench

// 5c. The baseline a user would write instead of shadowfilter: the whole ESM pipeline with the
// trilinear mips lookup in OpenCV on the host, beside ours (sf::Pipeline on the OpenCL device)
// on the same data in the same run, stage by stage (docs/bench_opencv.md).
//
// Data: bench_pipeline.cpp's. A size x size depth map of white noise (random_floats seed 9) and
// 1920x1080 receivers: rx 1 the coherent camera sweep (coherent_receivers: footprints from the
// map's screen derivatives), rx 0 random u, v, d with footprints uniform in [1, 8] (seeds 10-13).
// c = 80 (EsmOptions), blur radius R with sigma (2R+1)/6 (default_blur_sigma). Smoke mode: 512
// and screen()'s 320x180 receivers, the same check (docs/bench_opencv.md).
//
// The OpenCV pipeline, all CV_32F, cv::setNumThreads(2), stages timed separately (host wall):
//   transform   B = exp(c (z - 1/2)): depth.convertTo(c, -c/2) then cv::exp (esm.clh's centring).
//   blur        cv::GaussianBlur, ksize 2R+1, sigma (2R+1)/6 both ways, BORDER_REPLICATE (our
//               blur clamps to the edge).
//   pyramid     levels 1 .. top (1x1) by cv::resize(INTER_AREA) to ((w+1)/2, (h+1)/2): for the
//               even sizes of every level of a power-of-two map that is exactly the 2x2 mean of
//               pyramid.cl (0.25 (a + b + c + d), only the order of the additions differs).
//   lookup      trilinear at LOD l = min(log2(max(f, 1)), top) (sf_lod): level k weighs
//               max(0, 1 - |l - k|), which is 1 - t on k0 = floor(l) and t on k0 + 1, as
//               sf_lookup_trilinear; each level of [floor(min l), ceil(max l)] is sampled for
//               every receiver by cv::remap(INTER_LINEAR, BORDER_REPLICATE) at
//               (u w_k - 1/2, v h_k - 1/2) and accumulated with its weight (accumulateProduct);
//               then v = min(exp(min(c (1/2 - d), 88)) Bbar, 1) (SF_ESM_VISIBILITY).
// Ours: sf::Pipeline (transform, blur, joined mip chain, reconstruct), stage times from the
// profiling events, end to end host wall time of prefilter + reconstruct + wait. OpenCV's end to
// end time is the wall time of its four stages in a row (the manual time of both benchmarks).
//
// Same math check: the OpenCV benchmark runs ours once on its data and compares visibilities
// over all receivers. cv::remap quantises its bilinear weights to 1/32 (INTER_TAB_SIZE), which
// ESM's exponential basis amplifies (up to 0.6 in v on white-noise depth), so the check has two
// parts, each within kTolerance or the benchmark fails (SkipWithError):
//   max_abs_diff_exact  the OpenCV levels looked up with exact bilinear weights (exact_lookup)
//                       against ours: transform, blur, pyramid, LOD, weights and reconstruction;
//   over_remap_bound    the cv::remap pipeline's |v - v_ours| beyond that quantisation's bound
//                       (remap_bound) at every receiver.
// max_abs_diff (cv::remap pipeline vs ours) and remap_over_1_255 (the fraction of receivers
// more than 1/255 apart) are reported as they are: what the user's baseline costs in accuracy.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "bench_common.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::bench {
namespace {

constexpr double kTolerance = 1e-3;

// bench_pipeline.cpp's inputs, made once per (size, rx) and shared by both benchmarks.
struct EsmInputs : EsmFrame {
  int n = 0;
};
const EsmInputs& inputs(int n, bool coherent) {
  static std::map<std::pair<int, bool>, EsmInputs> cache;
  auto [it, fresh] = cache.try_emplace({n, coherent});
  EsmInputs& in = it->second;
  if (fresh) {
    static_cast<EsmFrame&>(in) = esm_frame(n, coherent);
    in.n = n;
  }
  return in;
}

// Like for like: the OpenCV pipeline is plain ESM, so ours runs without the z-max classification
// that EsmClassify::Auto adds for esm (its fall-back changes flagged receivers' visibility).
FilterOptions esm_options(int radius) {
  FilterOptions opt;
  opt.blur.radius = radius;
  opt.lookup.kind = Lookup::Mips;
  opt.esm_classify.mode = EsmClassify::None;
  return opt;
}

// Seconds of each stage of one run.
struct Stages {
  double transform = 0, blur = 0, pyramid = 0, lookup = 0;
  double sum() const { return transform + blur + pyramid + lookup; }
  void add(const Stages& s) { transform += s.transform, blur += s.blur, pyramid += s.pyramid, lookup += s.lookup; }
};

void set_stage_counters(benchmark::State& state, const Stages& sum, int runs, double e2e) {
  if (runs <= 0) return;
  state.counters["transform_ms"] = 1e3 * sum.transform / runs;
  state.counters["blur_ms"] = 1e3 * sum.blur / runs;
  state.counters["mips_ms"] = 1e3 * sum.pyramid / runs;
  state.counters["lookup_ms"] = 1e3 * sum.lookup / runs;  // lookup + reconstruction
  state.counters["stage_sum_ms"] = 1e3 * sum.sum() / runs;
  state.counters["e2e_ms"] = 1e3 * e2e;
}

// The OpenCV pipeline on host images (see the header comment).
class CvEsm {
 public:
  CvEsm(const EsmInputs& in, float c, int radius)
      : c_(c),
        ksize_(2 * radius + 1),
        sigma_(default_blur_sigma(radius)),
        depth_(in.n, in.n, CV_32F, const_cast<float*>(in.depth.data())),
        u_(screen().height, screen().width, CV_32F, const_cast<float*>(in.u.data())),
        v_(screen().height, screen().width, CV_32F, const_cast<float*>(in.v.data())),
        d_(screen().height, screen().width, CV_32F, const_cast<float*>(in.d.data())),
        f_(screen().height, screen().width, CV_32F, const_cast<float*>(in.f.data())) {
    int w = in.n, h = in.n;
    levels_.emplace_back();
    while (w > 1 || h > 1) {
      w = (w + 1) / 2, h = (h + 1) / 2;
      levels_.emplace_back(h, w, CV_32F);
    }
  }

  void transform() {
    depth_.convertTo(arg_, CV_32F, c_, -0.5 * c_);
    cv::exp(arg_, basis_);
  }
  void blur() { cv::GaussianBlur(basis_, levels_[0], cv::Size(ksize_, ksize_), sigma_, sigma_, cv::BORDER_REPLICATE); }
  void pyramid() {
    for (size_t k = 1; k < levels_.size(); ++k) {
      const cv::Mat& src = levels_[k - 1];
      cv::resize(src, levels_[k], cv::Size((src.cols + 1) / 2, (src.rows + 1) / 2), 0, 0, cv::INTER_AREA);
    }
  }
  void lookup() {
    const int top = int(levels_.size()) - 1;
    cv::max(f_, 1.0, lod_);  // f is finite here
    cv::log(lod_, lod_);
    lod_.convertTo(lod_, CV_32F, 1.0 / std::log(2.0));
    cv::min(lod_, double(top), lod_);
    double lo = 0, hi = 0;
    cv::minMaxLoc(lod_, &lo, &hi);
    const int k_first = int(std::floor(lo)), k_last = std::min(int(std::ceil(hi)), top);
    bbar_.create(u_.rows, u_.cols, CV_32F);
    bbar_.setTo(0);
    for (int k = k_first; k <= k_last; ++k) {
      const cv::Mat& level = levels_[k];
      u_.convertTo(mapx_, CV_32F, level.cols, -0.5);
      v_.convertTo(mapy_, CV_32F, level.rows, -0.5);
      cv::remap(level, sample_, mapx_, mapy_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      cv::absdiff(lod_, double(k), weight_);
      weight_.convertTo(weight_, CV_32F, -1.0, 1.0);
      cv::max(weight_, 0.0, weight_);
      cv::accumulateProduct(weight_, sample_, bbar_);
    }
    d_.convertTo(arg_rx_, CV_32F, -c_, 0.5 * c_);
    cv::min(arg_rx_, 88.0, arg_rx_);
    cv::exp(arg_rx_, arg_rx_);
    cv::multiply(bbar_, arg_rx_, vis_);
    cv::min(vis_, 1.0, vis_);
  }
  Stages run() {
    Stages s;
    s.transform = wall_seconds([&] { transform(); });
    s.blur = wall_seconds([&] { blur(); });
    s.pyramid = wall_seconds([&] { pyramid(); });
    s.lookup = wall_seconds([&] { lookup(); });
    return s;
  }
  const cv::Mat& visibility() const { return vis_; }
  const std::vector<cv::Mat>& levels() const { return levels_; }

 private:
  double c_;
  int ksize_;
  double sigma_;
  cv::Mat depth_, u_, v_, d_, f_;
  cv::Mat arg_, basis_;
  std::vector<cv::Mat> levels_;  // levels_[0]: the blurred basis
  cv::Mat lod_, mapx_, mapy_, sample_, weight_, bbar_, arg_rx_, vis_;
};

// Ours on the device: the buffers of one (size, rx), a Pipeline, and one timed run.
struct Ours {
  Pipeline pipe;
  cl::Buffer depth, vis;
  DeviceReceivers rx;
  Ours(const EsmInputs& in, int radius)
      : pipe(runtime_ptr(), esm_options(radius), in.n, in.n),
        depth(to_device(in.depth)),
        vis(device_buffer(screen().count() * sizeof(float))) {
    rx.count = screen().count();
    rx.u = to_device(in.u), rx.v = to_device(in.v), rx.d = to_device(in.d), rx.f = to_device(in.f);
  }
  // End to end wall seconds; the stages from the profiling events into `stages`.
  double run(Stages& stages) {
    const double wall = wall_seconds([&] {
      EventList filtered{pipe.prefilter(depth)};
      pipe.reconstruct(rx, vis, &filtered).wait();
    });
    const StageTimes t = pipe.times();
    stages = {t.transform, t.blur, t.pyramid, t.reconstruct};
    return wall;
  }
  std::vector<float> visibility() {
    std::vector<float> out(rx.count);
    runtime().queue().enqueueReadBuffer(vis, CL_TRUE, 0, out.size() * sizeof(float), out.data());
    return out;
  }
};

constexpr int kWarmups = 2;

void BM_OursEsmMips(benchmark::State& state) {
  const int n = int(state.range(0)), radius = int(state.range(1));
  const EsmInputs& in = inputs(n, state.range(2) == 1);
  Ours ours(in, radius);
  Stages sum, s;
  int calls = 0;
  const double e2e = time_runs(
      state,
      [&] {
        const double wall = ours.run(s);
        if (calls++ >= kWarmups) sum.add(s);  // the timed runs only
        return wall;
      },
      kWarmups);
  set_stage_counters(state, sum, calls - kWarmups, e2e);
  state.counters["threads"] = double(runtime().info().compute_units);
}

// The OpenCV pipeline's lookup redone exactly, in double, on the OpenCV levels (sf_lookup_trilinear
// with float texel coordinates as the kernel rounds them), and per receiver the most that
// cv::remap's weight quantisation can move it: 1/64 texel in x and in y on each level, at most
// (1/64 + 1/64) of the range of the level's four taps, times exp(c (1/2 - d)).
struct ExactLookup {
  std::vector<double> vis, remap_bound;
};
ExactLookup exact_lookup(const EsmInputs& in, const std::vector<cv::Mat>& levels, double c) {
  ExactLookup out;
  const size_t count = in.u.size();
  out.vis.resize(count), out.remap_bound.resize(count);
  const int top = int(levels.size()) - 1;
  for (size_t i = 0; i < count; ++i) {
    const double lod = std::log2(std::max(double(in.f[i]), 1.0));
    int k0 = int(std::floor(lod));
    double t = lod - k0;
    if (k0 >= top) k0 = top, t = 0;
    double bbar = 0, range = 0;
    for (int j = 0; j < (t > 0 ? 2 : 1); ++j) {
      const cv::Mat& L = levels[k0 + j];
      const int w = L.cols, h = L.rows;
      const double x = std::fmaf(in.u[i], float(w), -0.5f), y = std::fmaf(in.v[i], float(h), -0.5f);
      const double xf = std::floor(x), yf = std::floor(y), ax = x - xf, ay = y - yf;
      const int x0 = std::clamp(int(xf), 0, w - 1), x1 = std::clamp(int(xf) + 1, 0, w - 1);
      const int y0 = std::clamp(int(yf), 0, h - 1), y1 = std::clamp(int(yf) + 1, 0, h - 1);
      const double t00 = L.at<float>(y0, x0), t01 = L.at<float>(y0, x1);
      const double t10 = L.at<float>(y1, x0), t11 = L.at<float>(y1, x1);
      const double b = (1 - ay) * ((1 - ax) * t00 + ax * t01) + ay * ((1 - ax) * t10 + ax * t11);
      const double lvl_range = std::max({t00, t01, t10, t11}) - std::min({t00, t01, t10, t11});
      const double wk = j == 0 ? 1 - t : t;
      bbar += wk * b;
      range += wk * lvl_range;
    }
    const double e = std::exp(std::min(c * (0.5 - in.d[i]), 88.0));
    out.vis[i] = std::min(e * bbar, 1.0);
    out.remap_bound[i] = e * range / 32.0;
  }
  return out;
}

void BM_OpenCvEsmMips(benchmark::State& state) {
  const int n = int(state.range(0)), radius = int(state.range(1));
  const EsmInputs& in = inputs(n, state.range(2) == 1);
  cv::setNumThreads(2);
  const double c = EsmOptions{}.c;
  CvEsm cv_esm(in, float(c), radius);
  // Same math: ours once on the same inputs, against one OpenCV run.
  double max_diff = 0, max_exact = 0, max_excess = 0;
  size_t partial = 0, remap_over = 0;
  {
    Ours ours(in, radius);
    Stages ignored;
    ours.run(ignored);
    const std::vector<float> ref = ours.visibility();
    cv_esm.run();
    const cv::Mat& vis = cv_esm.visibility();
    const ExactLookup ex = exact_lookup(in, cv_esm.levels(), c);
    for (size_t i = 0; i < in.u.size(); ++i) {
      const double a = vis.ptr<float>()[i], b = ref[i];
      const double diff = std::isfinite(a) ? std::fabs(a - b) : 1e9;
      max_diff = std::max(max_diff, diff);
      max_exact = std::max(max_exact, std::fabs(ex.vis[i] - b));
      max_excess = std::max(max_excess, diff - std::min(ex.remap_bound[i], 1.0));
      partial += b > 0.0f && b < 1.0f;
      remap_over += diff > 1.0 / 255;
    }
  }
  state.counters["max_abs_diff"] = max_diff;         // cv::remap pipeline vs ours
  state.counters["max_abs_diff_exact"] = max_exact;  // exact bilinear on OpenCV's levels vs ours
  state.counters["over_remap_bound"] = max_excess;   // largest |diff| beyond the quantisation bound
  state.counters["remap_over_1_255"] = double(remap_over) / in.u.size();  // fraction of receivers
  state.counters["tolerance"] = kTolerance;
  state.counters["partial_fraction"] = double(partial) / in.u.size();  // receivers with 0 < v < 1
  if (!(max_exact <= kTolerance) || !(max_excess <= kTolerance)) {
    state.SkipWithError(("OpenCV visibility differs from ours: exact lookup " + std::to_string(max_exact) +
                         ", beyond cv::remap's quantisation " + std::to_string(max_excess) + " > " +
                         std::to_string(kTolerance))
                            .c_str());
    return;
  }
  Stages sum, s;
  int calls = 0;
  const double e2e = time_runs(
      state,
      [&] {
        const double wall = wall_seconds([&] { s = cv_esm.run(); });
        if (calls++ >= kWarmups) sum.add(s);
        return wall;
      },
      kWarmups);
  set_stage_counters(state, sum, calls - kWarmups, e2e);
  state.counters["threads"] = cv::getNumThreads();
}

}  // namespace

void register_opencv_esm() {
  // Ours right before OpenCV at every size, so that a ratio compares runs under the same load
  // (--benchmark_enable_random_interleaving=true interleaves their repetitions).
  // rx 1: the coherent camera sweep; rx 0: random receivers.
  for (int64_t size : sizes({512, 2048, 4096}))
    for (int64_t rx : {1, 0}) {
      configure(benchmark::RegisterBenchmark("esm_vs_opencv/ours", BM_OursEsmMips))
          ->ArgNames({"size", "R", "rx"})
          ->Args({size, 3, rx});
      configure(benchmark::RegisterBenchmark("esm_vs_opencv/opencv", BM_OpenCvEsmMips))
          ->ArgNames({"size", "R", "rx"})
          ->Args({size, 3, rx});
    }
}

}  // namespace sf::bench

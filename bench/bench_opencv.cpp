// 3b. The CPU baseline: cv::GaussianBlur on the same CV_32F image, ksize 2R+1, the same sigma
// ((2R+1)/6), BORDER_REPLICATE (= clamp-to-edge), on both cores. Host wall time.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_common.hpp"
#include "shadowfilter/blur.hpp"

namespace sf::bench {
namespace {

void BM_OpenCvGaussianBlur(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int radius = static_cast<int>(state.range(1));
  cv::setNumThreads(2);
  const auto values = random_floats(size_t(n) * n, 3);
  const cv::Mat src(n, n, CV_32F, const_cast<float*>(values.data()));
  cv::Mat dst(n, n, CV_32F);
  const int ksize = 2 * radius + 1;
  const double sigma = default_blur_sigma(radius);
  const double s = time_runs(state, [&] {
    return wall_seconds(
        [&] { cv::GaussianBlur(src, dst, cv::Size(ksize, ksize), sigma, sigma, cv::BORDER_REPLICATE); });
  });
  state.counters["threads"] = cv::getNumThreads();
  set_throughput(state, 4.0 * sizeof(float) * n * n, double(n) * n, s);
}

// One cv::pyrDown level (5x5 Gaussian + decimation) of a full-size image: the OpenCV baseline of
// our first mip level (the 2x2 mean of bench_pyramid.cpp's chain, which then builds the rest).
void BM_OpenCvPyrDown(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  cv::setNumThreads(2);
  const auto values = random_floats(size_t(n) * n, 7);
  const cv::Mat src(n, n, CV_32F, const_cast<float*>(values.data()));
  cv::Mat dst;
  const double s = time_runs(state, [&] { return wall_seconds([&] { cv::pyrDown(src, dst); }); });
  state.counters["threads"] = cv::getNumThreads();
  set_throughput(state, 4.0 * n * n * 1.25, double(n) * n, s);
}

}  // namespace

void register_opencv_pyrdown() {
  configure(benchmark::RegisterBenchmark("mips/opencv_pyrDown_one_level", BM_OpenCvPyrDown))
      ->ArgName("size")
      ->ArgsProduct({sizes({512, 2048, 4096})});
}

void register_opencv_blur(int size, int radius) {
  configure(benchmark::RegisterBenchmark("blur/opencv_GaussianBlur", BM_OpenCvGaussianBlur))
      ->ArgNames({"size", "R"})
      ->Args({size, radius});
}

}  // namespace sf::bench

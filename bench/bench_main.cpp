// sf_bench entry point: measures the reference copy bandwidth first (every bw_fraction is
// relative to it), then registers the suites in a fixed order and runs them. Each OpenCV blur
// runs right after ours at the same size and radius, so that a ratio compares runs made under
// the same load on a shared machine.
#include <cstdio>
#include <string>

#include "bench_common.hpp"

#ifdef SF_HAVE_OPENCV
namespace sf::bench {
void register_opencv_esm();  // bench_opencv_esm.cpp: the ESM pipeline in OpenCV beside ours
}
#endif

int main(int argc, char** argv) {
  using namespace sf::bench;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  const auto& info = runtime().info();
  const double bw = measure_copy_bandwidth();
  set_reference_bandwidth(bw);
  benchmark::AddCustomContext("opencl_device",
                              info.device_name + " (" + info.platform_name + " " + info.driver_version + ")");
  benchmark::AddCustomContext("opencl_compute_units", std::to_string(info.compute_units));
  benchmark::AddCustomContext("reference_copy_GBps", std::to_string(bw * 1e-9));
  std::fprintf(stderr, "device: %s, reference copy bandwidth %.2f GB/s (read + write)\n", info.device_name.c_str(),
               bw * 1e-9);

  register_copy();
  register_transform();
  register_blur();
  register_reconstruct();
  register_pipeline();
  register_layered();
  register_pyramid();
  register_coverage();
  register_classify();
#ifdef SF_HAVE_OPENCV
  register_opencv_pyrdown();
  register_opencv_esm();
#endif
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

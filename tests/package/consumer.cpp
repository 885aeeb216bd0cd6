// A consumer of the core library alone (tests/package), compiled with its own opencl.hpp
// settings: the public headers compile, a pipeline runs on the default device, an OpenCL failure
// inside the library arrives as sf::DeviceError, and the kernel prelude is complete.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "shadowfilter/embed.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/pipeline.hpp"

namespace {

bool check(bool ok, const char* what) {
  std::printf("consumer: %s: %s\n", what, ok ? "ok" : "WRONG");
  return ok;
}

}  // namespace

int main() {
  bool ok = true;
  sf::FilterOptions opt;  // esm by default
  const sf::KernelPrelude p = sf::kernel_prelude(opt);
  ok &= check(p.files.size() == 5 && p.source.find("sf_visibility") != std::string::npos &&
                  p.build_options.find("-DSF_STORAGE=0") != std::string::npos && !sf::kernel_files().empty(),
              "kernel prelude");

  auto rt = sf::Runtime::create();
  // A 16x16 map at depth 0.5: a receiver in front of it is lit, one behind it in shadow.
  sf::HostImage depth(16, 16, 1, 0.5f);
  sf::Receivers rx;
  rx.width = 2;
  rx.height = 1;
  rx.u = {0.5f, 0.5f};
  rx.v = {0.5f, 0.5f};
  rx.d = {0.4f, 0.6f};
  const sf::FilterResult r = sf::filter(rt, opt, depth, rx);
  ok &= check(r.visibility.data[0] == 1.0f && r.visibility.data[1] < 1e-3f, "pipeline on the default device");

  // sm copies its depth buffer: one smaller than the map makes clEnqueueCopyBuffer fail.
  sf::FilterOptions sm;
  sm.method = "sm";
  sf::Pipeline pipe(rt, sm, 64, 64);
  cl_int err = CL_SUCCESS;
  cl::Buffer small(rt->context(), CL_MEM_READ_WRITE, 64, nullptr, &err);
  bool device_error = false;
  try {
    pipe.prefilter(small);
  } catch (const sf::DeviceError& e) {
    device_error = std::string(e.what()).find("CL_INVALID_VALUE") != std::string::npos;
    std::printf("consumer: %s\n", e.what());
  }
  ok &= check(err == CL_SUCCESS && device_error, "an OpenCL failure arrives as sf::DeviceError");
  return ok ? 0 : 1;
}

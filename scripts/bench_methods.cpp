// Issue 3 figures harness (kept out of bench/ while the bench suite is being rewritten; move it
// there as a Google Benchmark when that lands). Run: scripts/bench_methods.sh [reps]
// Env: ONLY=substring of method_storage_order, NOREC=1 skips reconstruction, WG=work-group size,
// XVEC=transform vector width (default 16; the table also times width 1, one texel per item).
// Transform throughput per method/storage vs copy bandwidth (2048x2048), memory per texel,
// reconstruction time for 1920x1080 point receivers. Median of N device times (profiling events).
#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "shadowfilter/kernels.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/runtime.hpp"

using namespace sf;

static double median_time(int reps, const std::function<cl::Event()>& f) {
  f().wait();  // warm-up (program build, first touch)
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    cl::Event e = f();
    e.wait();
    t.push_back(event_seconds(e));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

static const char* kCopy = R"CL(
__kernel void copy1(__global const float* restrict s, __global float* restrict d) { size_t i = get_global_id(0); d[i] = s[i]; }
__kernel void copy16(__global const float16* restrict s, __global float16* restrict d) { size_t i = get_global_id(0); d[i] = s[i]; }
)CL";

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::atoi(argv[1]) : 9;
  auto rt = Runtime::create();
  auto& q = rt->queue();
  const size_t copy_bytes = size_t(64) << 20;
  std::vector<float> junk(copy_bytes / 4, 0.5f);
  cl::Buffer a(rt->context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, copy_bytes, junk.data());
  cl::Buffer b(rt->context(), CL_MEM_READ_WRITE, copy_bytes);
  cl::Program cp(rt->context(), kCopy);
  cp.build({rt->device()}, "-cl-std=CL1.2");
  double best_copy = 1e9;
  best_copy = std::min(best_copy, median_time(reps, [&] {
    cl::Event e;
    q.enqueueCopyBuffer(a, b, 0, 0, copy_bytes, nullptr, &e);
    return e;
  }));
  for (auto [name, per] : {std::pair<const char*, size_t>{"copy1", 1}, {"copy16", 16}}) {
    cl::Kernel k(cp, name);
    k.setArg(0, a);
    k.setArg(1, b);
    best_copy = std::min(best_copy, median_time(reps, [&] {
      cl::Event e;
      q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(copy_bytes / 4 / per), cl::NullRange, nullptr, &e);
      return e;
    }));
  }
  const double copy_bw = 2.0 * copy_bytes / best_copy;  // read + write
  std::printf("device: %s\ncopy bandwidth (best median of clEnqueueCopyBuffer, copy1, copy16; 64 MiB): %.2f GB/s\n\n",
              rt->info().device_name.c_str(), copy_bw / 1e9);

  const int W = 2048, H = 2048;
  std::vector<float> depth(size_t(W) * H);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> unit(0, 1);
  for (auto& z : depth) z = unit(rng);
  cl::Buffer zb(rt->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, depth.size() * 4, depth.data());
  const size_t NR = 1920 * 1080;
  std::vector<float> u(NR), v(NR), d(NR);
  // Coherent receivers, like a camera view: (u, v) follow the pixel position (a rotated, scaled
  // mapping covering most of the map), d is a smooth ramp plus jitter.
  for (size_t i = 0; i < NR; ++i) {
    const float x = float(i % 1920) / 1920, y = float(i / 1920) / 1080;
    u[i] = 0.05f + 0.8f * x + 0.1f * y;
    v[i] = 0.05f + 0.1f * x + 0.8f * y;
    d[i] = 0.3f + 0.4f * y + 0.05f * unit(rng);
  }
  cl::Buffer ub(rt->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, NR * 4, u.data());
  cl::Buffer vb(rt->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, NR * 4, v.data());
  cl::Buffer db(rt->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, NR * 4, d.data());
  cl::Buffer out(rt->context(), CL_MEM_READ_WRITE, NR * 4);

  struct Case { std::string method; Storage s; int order; };
  std::vector<Case> cases = {{"sm", Storage::F32, 0}, {"pcf", Storage::F32, 0},
      {"esm", Storage::F32, 0}, {"esm", Storage::F16, 0}, {"vsm", Storage::F32, 0}, {"vsm", Storage::F16, 0},
      {"vsm", Storage::Unorm16, 0}, {"evsm2", Storage::F32, 0}, {"evsm2", Storage::F16, 0},
      {"evsm4", Storage::F32, 0}, {"evsm4", Storage::F16, 0}, {"msm", Storage::F32, 0},
      {"msm", Storage::Unorm16, 0}, {"msm-hausdorff", Storage::F32, 0}};
  for (int M : {4, 8, 16})
    for (Storage s : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8}) cases.push_back({"csm", s, M});
  cases.push_back({"csm", Storage::F32, 32});
  std::printf("%-14s %-8s %4s %9s %12s %9s %8s %10s %8s %14s\n", "method", "storage", "M", "B/texel",
              "transform ms", "GB/s", "of copy", "w=1 ms", "of copy", "reconstruct ms");
  const char* only = std::getenv("ONLY");
  const int wg = std::getenv("WG") ? std::atoi(std::getenv("WG")) : 0;
  const int xvec = std::getenv("XVEC") ? std::atoi(std::getenv("XVEC")) : 16;
  const bool skip_rec = std::getenv("NOREC") != nullptr;
  for (const Case& c : cases) {
    if (only && (c.method + "_" + storage_name(c.s) + "_" + std::to_string(c.order)).find(only) == std::string::npos) continue;
    FilterOptions o;
    o.schedule.work_group_size = wg;
    o.schedule.transform_vector_width = xvec;
    o.method = c.method;
    o.storage = c.s;
    if (c.order) o.csm.order = c.order;
    if (c.method == "esm" && c.s == Storage::F16) o.esm.c = 20;
    if (c.method == "pcf") o.blur.radius = 2;
    const MethodDesc& m = find_method(c.method);
    const size_t bpt = basis_bytes_per_texel(m, o);
    cl::Buffer basis(rt->context(), CL_MEM_READ_WRITE, bpt * W * H);
    FilterOptions o1 = o;
    o1.schedule.transform_vector_width = 1;
    const double t1 = m.raw_depth ? 0 : median_time(reps, [&] { return enqueue_transform(*rt, m, o1, zb, W, H, basis); });
    const double tt = median_time(reps, [&] { return enqueue_transform(*rt, m, o, zb, W, H, basis); });
    const double bytes = double(W) * H * (4 + bpt);
    const double tr = skip_rec ? 0 : median_time(reps, [&] {
      return enqueue_reconstruct_points(*rt, m, o, basis, W, H, ub, vb, db, out, NR);
    });
    std::printf("%-14s %-8s %4s %9zu %12.2f %9.2f %7.0f%% %10.2f %7.0f%% %14.2f%s\n", c.method.c_str(),
                storage_name(c.s), c.order ? std::to_string(c.order).c_str() : "-",
                m.raw_depth ? size_t(0) : bpt, tt * 1e3, bytes / tt / 1e9, 100 * bytes / tt / copy_bw,
                t1 * 1e3, t1 > 0 ? 100 * bytes / t1 / copy_bw : 0.0, tr * 1e3,
                c.method == "pcf" ? "  (R = 2)" : "");
  }
  return 0;
}

// 4. ESM reconstruction on a 2048x2048 filtered basis (smoke mode: smoke_size(2048) and screen()
// throughout): 1920x1080 receivers in points mode
// (u, v, d read + visibility written = 16 bytes per receiver, plus the gathers), bilinear or
// trilinear over its mip chain (footprints read: 20 bytes), random or coherent receivers
// (bench_pipeline.cpp), and grid mode at 2048x2048 (d and one basis texel read + visibility
// written = 12 bytes). vec: receivers per work-item (ScheduleOptions::reconstruct_vector_width);
// joined 1: the mip levels in one buffer, as the pipeline keeps them (kernels.cpp).
// Bounds (esm_reconstruct/bound_*): the same receivers through kernels that only stream
// u, v, d -> out, or only gather the 4 (bilinear) / 8 (levels 0 and 1) texels with the least
// index math: what reconstruction costs at best on this device.
#include "bench_common.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf::bench {
namespace {

int map_size() { return smoke_size(2048); }
size_t receiver_count() { return screen().count(); }

// The filtered basis and its mip chain, in two buffers (buf, chain) and as the pipeline keeps
// them: one buffer (joined) with level 0 at 0 and the chain (joined_chain, a sub-buffer) after it.
struct Basis {
  const int n = map_size();
  cl::Buffer buf = device_buffer(size_t(n) * n * sizeof(float));
  cl::Buffer chain, joined, joined_chain;
  Basis() {
    cl::Buffer depth = to_device(random_floats(size_t(n) * n, 4, 0.2f, 0.8f));
    const FilterOptions esm;  // c = 80
    enqueue_transform(runtime(), *sf::method("esm"), esm, n, n, depth, buf).wait();
    const ImageShape shape{n, n, 1, 4};
    const size_t level0 = shape.bytes(), chain_bytes = mip_layout(n, n, 1).chain_values * sizeof(float);
    chain = device_buffer(chain_bytes);
    enqueue_pyramid(runtime(), Reduce::Mean, Storage::F32, {}, shape, buf, chain).wait();
    joined = device_buffer(level0 + chain_bytes + 4);  // one padding value (kernels.cpp)
    cl_buffer_region region{level0, chain_bytes + 4};
    joined_chain = joined.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &region);
    runtime().queue().enqueueCopyBuffer(buf, joined, 0, 0, level0);
    runtime().queue().enqueueCopyBuffer(chain, joined, 0, level0, chain_bytes);
    runtime().queue().finish();
  }
};

const Basis& basis() {
  static Basis b;
  return b;
}

struct Rx {
  cl::Buffer u, v, d, f;
};

// rx 0: random (footprints uniform in [1, 8]); rx 1: coherent.
const Rx& receivers(bool coherent) {
  static Rx r[2];
  Rx& x = r[coherent ? 1 : 0];
  if (!x.u()) {
    const size_t count = receiver_count();
    if (coherent) {
      std::vector<float> u, v, d, f;
      coherent_receivers(map_size(), u, v, d, f);
      x.u = to_device(u), x.v = to_device(v), x.d = to_device(d), x.f = to_device(f);
    } else {
      x.u = to_device(random_floats(count, 5)), x.v = to_device(random_floats(count, 6));
      x.d = to_device(random_floats(count, 7));
      x.f = to_device(random_floats(count, 13, 1.0f, 8.0f));
    }
  }
  return x;
}

void BM_ReconstructPoints(benchmark::State& state) {
  const bool mips = state.range(0) == 1;
  const Rx& rx = receivers(state.range(1) == 1);
  const int n = map_size();
  const size_t count = receiver_count();
  cl::Buffer vis = device_buffer(count * sizeof(float));
  FilterOptions opt;
  opt.schedule.reconstruct_vector_width = static_cast<int>(state.range(2));
  LookupBuffers lookup;
  const bool joined = mips && state.range(3) == 1;
  if (mips) {
    opt.lookup.kind = lookup.kind = Lookup::Mips;
    lookup.chain = joined ? basis().joined_chain : basis().chain;
    lookup.footprint = rx.f;
  }
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_reconstruct_points(runtime(), *sf::method("esm"), opt, n, n, count, 0,
                                             joined ? basis().joined : basis().buf, &lookup, rx.u, rx.v, rx.d, vis);
    e.wait();
    return event_seconds(e);
  });
  state.counters["ns_per_receiver"] = s * 1e9 / count;
  set_throughput(state, (mips ? 20.0 : 16.0) * count, count, s);
}

void BM_ReconstructGrid(benchmark::State& state) {
  const int n = map_size();
  const size_t count = size_t(n) * n;
  cl::Buffer d = to_device(random_floats(count, 8));
  cl::Buffer vis = device_buffer(count * sizeof(float));
  const FilterOptions opt;
  const double s = time_runs(state, [&] {
    cl::Event e = enqueue_reconstruct_grid(runtime(), *sf::method("esm"), opt, n, n, basis().buf, d, vis);
    e.wait();
    return event_seconds(e);
  });
  set_throughput(state, 3.0 * sizeof(float) * count, count, s);
}

// One receiver per work-item, PoCL vectorises across work-items. taps 0: u + v + d only;
// 4: the bilinear texels of level 0; 8: those of levels 0 and 1 (a trilinear lookup's reads).
const char* kBoundSource = R"CLC(
__kernel void bound_stream(__global const float* restrict u, __global const float* restrict v,
                           __global const float* restrict d, __global float* restrict out) {
  const int i = get_global_id(0);
  out[i] = u[i] + v[i] + d[i];
}
inline float taps4(__global const float* restrict img, int w, float u, float v) {
  const int x = clamp((int)(u * w), 0, w - 2), y = clamp((int)(v * w), 0, w - 2);
  const int a = y * w + x;
  return (img[a] + img[a + 1]) + (img[a + w] + img[a + w + 1]);
}
__kernel void bound_gather(__global const float* restrict l0, __global const float* restrict l1,
                           int w, __global const float* restrict u, __global const float* restrict v,
                           __global const float* restrict d, __global float* restrict out) {
  const int i = get_global_id(0);
  float s = d[i] + taps4(l0, w, u[i], v[i]);
#if TAPS == 8
  s += taps4(l1, w / 2, u[i], v[i]);
#endif
  out[i] = s;
}
)CLC";

void BM_ReconstructBound(benchmark::State& state) {
  const int taps = static_cast<int>(state.range(0));
  const Rx& rx = receivers(state.range(1) == 1);
  const size_t count = receiver_count();
  cl::Buffer out = device_buffer(count * sizeof(float));
  cl::Program p(runtime().context(), kBoundSource);
  p.build(("-cl-std=CL1.2 -DTAPS=" + std::to_string(taps)).c_str());
  cl::Kernel k(p, taps == 0 ? "bound_stream" : "bound_gather");
  if (taps == 0) {
    k.setArg(0, rx.u), k.setArg(1, rx.v), k.setArg(2, rx.d), k.setArg(3, out);
  } else {
    k.setArg(0, basis().buf), k.setArg(1, basis().chain), k.setArg(2, map_size());
    k.setArg(3, rx.u), k.setArg(4, rx.v), k.setArg(5, rx.d), k.setArg(6, out);
  }
  const double s = time_runs(state, [&] {
    cl::Event e;
    runtime().queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(count), cl::NullRange, nullptr, &e);
    e.wait();
    return event_seconds(e);
  });
  state.counters["ns_per_receiver"] = s * 1e9 / count;
  set_throughput(state, 16.0 * count, count, s);
}

}  // namespace

void register_reconstruct() {
  const std::string map = std::to_string(map_size());
  configure(benchmark::RegisterBenchmark(("esm_reconstruct/points_on_" + map).c_str(), BM_ReconstructPoints))
      ->ArgNames({"lookup", "rx", "vec", "joined"})
      ->ArgsProduct({{0}, {0, 1}, {1, 4, 8, 16}, {0}})
      ->ArgsProduct({{1}, {0, 1}, {1, 4, 8, 16}, {0, 1}});
  configure(benchmark::RegisterBenchmark("esm_reconstruct/grid", BM_ReconstructGrid))->ArgName("size")->Arg(map_size());
  configure(benchmark::RegisterBenchmark("esm_reconstruct/bound", BM_ReconstructBound))
      ->ArgNames({"taps", "rx"})
      ->Args({0, 0})
      ->Args({4, 0})
      ->Args({8, 0})
      ->Args({8, 1});
}

}  // namespace sf::bench

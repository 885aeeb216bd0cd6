// Mip pyramids (kernels/pyramid.cl) and the method-agnostic lookup kernel (lookup_values.cl).
#include <algorithm>
#include <string>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "pass_events.hpp"
#include "schedule_defaults.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf {
using detail::PassEvents;
namespace {

constexpr int kTile = 32;          // pyramid.cl SF_TILE
constexpr int kTileLevels = 5;     // levels per tile launch
constexpr int kWide = 4;           // pyramid.cl SF_WIDE: tiles side by side per work-item
constexpr int kTailMaxSide = 128;  // levels this small are finished by one work-item per channel

}  // namespace

MipLayout mip_layout(int width, int height, int channels) {
  if (width <= 0 || height <= 0 || channels <= 0) throw InputError("mip_layout: empty image");
  MipLayout L;
  L.channels = channels;
  L.levels.push_back({width, height, 0});
  size_t off = 0;
  int w = width, h = height;
  while (w > 1 || h > 1) {
    w = (w + 1) / 2;
    h = (h + 1) / 2;
    L.levels.push_back({w, h, off});
    off += size_t(channels) * w * h;
  }
  L.chain_values = off;
  return L;
}

namespace {

// The Gpu family (pyramid.cl, SF_PYRAMID_GPU): square groups of side g, log2(g) + 1 levels per
// launch, one launch per that many levels down to 1x1.
PassEvents enqueue_pyramid_groups(Runtime& rt, Reduce op, Storage storage, const cl::Buffer& level0,
                                  const cl::Buffer& chain, const ImageShape& shape, const MipLayout& L,
                                  const EventList* wait, int work_group) {
  const int items = gpu_group_items(
      rt, launch_defaults(ScheduleFamily::Gpu).pyramid_group * launch_defaults(ScheduleFamily::Gpu).pyramid_group,
      work_group);
  int side = 1;
  while (side * side * 4 <= items) side *= 2;
  cl::Kernel k;
  for (;;) {
    cl::Program p = rt.program({"common.clh", "storage.clh", "vecio.clh", "pyramid.cl"},
                               detail::BuildOptions()
                                   .storage(storage)
                                   .define("SF_REDUCE", static_cast<int>(op))
                                   .flag("SF_PYRAMID_GPU")
                                   .define("SF_PG", side)
                                   .str());
    k = cl::Kernel(p, "sf_pyramid_groups");
    if (side == 1 || kernel_group_limit(rt, k) >= size_t(side) * side) break;
    side /= 2;
  }
  int levels = 1;
  for (int g = side; g > 1; g /= 2) ++levels;
  PassEvents ev;
  EventList after;
  const EventList* deps = wait;
  for (int s = 0; s < L.top();) {
    const int m = std::min(levels, L.top() - s);
    detail::KernelArgs(k)
        .buffer(s == 0 ? level0 : chain)
        .value(static_cast<int>(L.levels[s].offset))
        .buffer(chain)
        .value(shape.width)
        .value(shape.height)
        .value(shape.channels)
        .value(s)
        .value(m);
    const size_t gw = size_t((L.levels[s + 1].width + side - 1) / side) * side;
    const size_t gh = size_t((L.levels[s + 1].height + side - 1) / side) * side;
    cl::Event e;
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(gw, gh, shape.channels), cl::NDRange(side, side, 1),
                                    deps, &e);
    if (!ev.first()) ev.first = e;
    ev.last = e;
    after = {e};
    deps = &after;
    s += m;
  }
  return ev;
}

}  // namespace

namespace {

PassEvents pyramid_passes(Runtime& rt, Reduce op, Storage storage, const cl::Buffer& level0, const cl::Buffer& chain,
                          const ImageShape& shape, const EventList* wait, const ScheduleOptions& schedule) try {
  const MipLayout L = mip_layout(shape.width, shape.height, shape.channels);
  PassEvents ev;
  if (L.top() == 0) {  // 1x1: nothing to build
    rt.queue().enqueueMarkerWithWaitList(wait, &ev.first);
    ev.last = ev.first;
    return ev;
  }
  if (resolve_family(rt, schedule.family) == ScheduleFamily::Gpu)
    return enqueue_pyramid_groups(rt, op, storage, level0, chain, shape, L, wait, schedule.gpu_work_group);
  cl::Program p = rt.program(
      {"common.clh", "storage.clh", "vecio.clh", "pyramid.cl"},
      detail::BuildOptions().storage(storage).define("SF_REDUCE", static_cast<int>(op)).define("SF_WIDE", kWide).str());
  const int W = shape.width, H = shape.height, N = shape.channels;
  const cl::Buffer* src = &level0;
  int s = 0, src_off = 0;
  EventList after;
  const EventList* deps = wait;
  auto launched = [&](const cl::Event& e) {
    if (!ev.first()) ev.first = e;
    ev.last = e;
    after = {e};
    deps = &after;
  };
  // Both kernels read level s of *src (at src_off) and write the levels after it into chain; the
  // tiles kernel takes the number of levels after these.
  auto level_args = [&](cl::Kernel& k) {
    return detail::KernelArgs(k).buffer(*src).value(src_off).buffer(chain).value(W).value(H).value(N).value(s);
  };
  while (s < L.top() && std::max(L.levels[s].width, L.levels[s].height) > kTailMaxSide) {
    const int m = std::min(kTileLevels, L.top() - s);
    cl::Kernel k(p, "sf_pyramid_tiles");
    level_args(k).value(m);
    const cl::NDRange global((L.levels[s].width + kTile * kWide - 1) / (kTile * kWide),
                             (L.levels[s].height + kTile - 1) / kTile, N);
    cl::Event e;
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global, cl::NDRange(1, 1, 1), deps, &e);
    launched(e);
    src = &chain;
    s += m;
    src_off = static_cast<int>(L.levels[s].offset);
  }
  if (s < L.top()) {
    cl::Kernel k(p, "sf_pyramid_tail");
    level_args(k);
    cl::Event e;
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(N), cl::NullRange, deps, &e);
    launched(e);
  }
  return ev;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pyramid", e);
}

}  // namespace

cl::Event enqueue_pyramid(Runtime& rt, Reduce op, Storage storage, const ScheduleOptions& schedule,
                          const ImageShape& shape, const cl::Buffer& level0, const cl::Buffer& chain, cl::Event* first,
                          const EventList* wait) try {
  const PassEvents ev = pyramid_passes(rt, op, storage, level0, chain, shape, wait, schedule);
  if (first) *first = ev.first;
  return ev.last;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_pyramid", e);
}

cl::Event enqueue_lookup_points(Runtime& rt, Storage storage, const ImageShape& shape, size_t count,
                                const LookupBuffers& lookup, const cl::Buffer& level0, const cl::Buffer& u,
                                const cl::Buffer& v, const cl::Buffer& out, const EventList* wait) try {
  const int aniso = detail::anisotropy(lookup.kind, lookup.jacobian, lookup.max_anisotropy);
  cl::Program p = rt.program({"common.clh", "storage.clh", "lookup.clh", "lookup_values.cl"},
                             detail::BuildOptions()
                                 .storage(storage)
                                 .define("SF_CHANNELS", shape.channels)
                                 .lookup(lookup.kind)
                                 .define_if(aniso > 1, "SF_ANISO", aniso)
                                 .str());
  cl::Kernel k(p, "sf_lookup_points");
  detail::KernelArgs(k)
      .buffer(level0)
      .optional(lookup.chain)
      .optional(lookup.sat)
      .value(shape.width)
      .value(shape.height)
      .buffer(u)
      .buffer(v)
      .optional(aniso > 1 ? lookup.jacobian : lookup.footprint)
      .buffer(out)
      .value(static_cast<int>(count));
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(std::max<size_t>(count, 1)), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_lookup_points", e);
}

}  // namespace sf

// Summed-area tables (kernels/sat.cl): double (or float-float) accumulation stored as float-float,
// the row prefix in transposed 8x8 blocks; one launch on CPUs (bands chained in start order),
// two elsewhere (band sums, then rows); the Gpu family scans rows in work-groups (three launches).
#include <algorithm>
#include <string>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "pass_events.hpp"
#include "schedule_defaults.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/sat.hpp"

namespace sf {
using detail::PassEvents;
namespace {
constexpr int kStrip = 256;  // columns per work-item of sf_sat_bands (SF_SAT_STRIP)
// A chained band's stored rows, read twice, the second time from L2/L3: at 2048^2 bands of
// 256 KiB to 2 MiB were within noise of each other, at 4096^2 1-2 MiB were best.
constexpr size_t kChainBandBytes = 1 << 20;

// Bands of `rows` rows (at most the image's) and how many cover the image.
void set_bands(int height, int rows, int& bands, int& band_rows) {
  band_rows = std::clamp(rows, 1, std::max(1, height));
  bands = (height + band_rows - 1) / band_rows;
}
}  // namespace

SatLayout sat_layout(const ImageShape& shape) {
  SatLayout L;
  const size_t W = size_t(shape.width), N = size_t(shape.channels);
  // Two launches: one work-item per band in the second. 16 bands keep two CPU cores busy while
  // the carries a band reads (the column sums of the bands above it, one double per column
  // each) stay a few percent of the image.
  const int two_bands = std::clamp(shape.height / 32, 1, 16);
  set_bands(shape.height, (shape.height + two_bands - 1) / two_bands, L.bands, L.band_rows);
  // One launch: bands small enough that their second read comes from cache, in multiples of 8
  // rows, and at least 8 of them per channel where the image has the rows.
  const size_t cache_rows = std::max<size_t>(8, kChainBandBytes / (W * shape.value_bytes) / 8 * 8);
  const int eighth = (shape.height + 63) / 64 * 8;  // ceil(H / 8) rounded up to 8
  set_bands(shape.height, int(std::min<size_t>(cache_rows, size_t(eighth))), L.chain_bands, L.chain_band_rows);
  L.pitch = (W + SatLayout::x0 + 16) & ~size_t(15);  // sf_sat_pitch
  L.plane_floats = L.pitch * (size_t(shape.height) + 1);
  L.table_floats = 2 * N * L.plane_floats;
  // Scratch entries are 8 bytes (2 floats): rows of W per band, 2 in two launches (sums, running
  // S row), 4 in the chain (sums, inclusive and exclusive carries, running S row), then the
  // chain's control ints.
  const size_t two = 4 * N * size_t(L.bands) * W;
  L.chain_ctl_offset = 8 * N * size_t(L.chain_bands) * W;
  L.chain_ctl_ints = 1 + N * size_t(L.chain_bands);
  const size_t chain = L.chain_ctl_offset + L.chain_ctl_ints;
  L.band_floats = std::max(two, chain);
  return L;
}

SatSchedule sat_schedule(const Runtime& rt, const ImageShape& shape) {
  // One band per channel while the channels fill the compute units; otherwise the chained launch
  // on CPUs and two launches elsewhere: the fastest of the three on each (docs/lookups.md has
  // the measurements).
  if (shape.channels >= int(std::max<cl_uint>(1, rt.info().compute_units))) return SatSchedule::PerChannel;
  return rt.info().type == "CPU" ? SatSchedule::Chained : SatSchedule::TwoLaunch;
}

namespace {

// SatSchedule::WorkGroupScan (sat.cl, SF_SAT_GPU): the rows' scan, the bands' column sums, the
// columns; bands of the two-launch layout (their scratch holds the band sums: N nb W entries).
PassEvents enqueue_sat_scan(Runtime& rt, const detail::BuildOptions& options, const cl::Buffer& src,
                            const cl::Buffer& table, const cl::Buffer& band_scratch, const ImageShape& shape,
                            const SatLayout& L, const EventList* wait, int work_group) {
  int items = gpu_group_items(rt, launch_defaults(ScheduleFamily::Gpu).sat_group, work_group);
  // Two rows of sf_acc (8 bytes) per item in local memory.
  while (items > 1 && size_t(items) * 16 > local_mem_bytes(rt)) items /= 2;
  for (;;) {
    const cl::Program p = rt.program({"common.clh", "storage.clh", "vecio.clh", "sat_accum.clh", "sat.cl"},
                                     detail::BuildOptions(options).flag("SF_SAT_GPU").define("SF_SAT_WG", items).str());
    cl::Kernel rows(p, "sf_sat_scan_rows"), bands(p, "sf_sat_scan_bands"), cols(p, "sf_sat_scan_cols");
    if (items > 1 && (kernel_group_limit(rt, rows) < size_t(items) || kernel_group_limit(rt, bands) < size_t(items) ||
                      kernel_group_limit(rt, cols) < size_t(items))) {
      items /= 2;
      continue;
    }
    const int W = shape.width, H = shape.height, N = shape.channels;
    detail::KernelArgs(rows).buffer(src).value(W).value(H).buffer(table);
    for (cl::Kernel* k : {&bands, &cols})
      detail::KernelArgs(*k).value(W).value(H).value(L.band_rows).value(L.bands).buffer(band_scratch).buffer(table);
    const size_t columns = size_t((W + items - 1) / items) * items;
    PassEvents ev;
    rt.queue().enqueueNDRangeKernel(rows, cl::NullRange, cl::NDRange(items, size_t(H) + 1, N), cl::NDRange(items, 1, 1),
                                    wait, &ev.first);
    EventList after{ev.first};
    if (L.bands > 1) {
      cl::Event e;
      rt.queue().enqueueNDRangeKernel(bands, cl::NullRange, cl::NDRange(columns, L.bands - 1, N),
                                      cl::NDRange(items, 1, 1), &after, &e);
      after = {e};
    }
    rt.queue().enqueueNDRangeKernel(cols, cl::NullRange, cl::NDRange(columns, L.bands, N), cl::NDRange(items, 1, 1),
                                    &after, &ev.last);
    return ev;
  }
}

}  // namespace

namespace {

PassEvents sat_passes(Runtime& rt, Storage storage, const cl::Buffer& src, const cl::Buffer& table,
                      const cl::Buffer& band_scratch, const ImageShape& shape, const EventList* wait,
                      const SatBuild& build, const ScheduleOptions& sched) try {
  SatLayout L = sat_layout(shape);
  const SatAccumulator accumulator = build.accumulator;
  SatSchedule schedule = build.schedule;
  const bool fp64 = accumulator == SatAccumulator::Auto ? rt.info().fp64 : accumulator == SatAccumulator::Double;
  if (fp64 && !rt.info().fp64)
    throw InputError("SAT: the double accumulator needs cl_khr_fp64, which '" + rt.info().device_name +
                     "' does not support");
  if (schedule == SatSchedule::Auto)
    schedule =
        resolve_family(rt, sched.family) == ScheduleFamily::Gpu ? SatSchedule::WorkGroupScan : sat_schedule(rt, shape);
  if (schedule == SatSchedule::WorkGroupScan)
    return enqueue_sat_scan(rt, detail::BuildOptions().storage(storage).define("SF_SAT_FP64", fp64 ? 1 : 0), src, table,
                            band_scratch, shape, L, wait, sched.gpu_work_group);
  detail::BuildOptions options;
  options.define("SF_SAT_STRIP", kStrip).storage(storage).define("SF_SAT_FP64", fp64 ? 1 : 0);
  if (build.chain_polls >= 0) options.define("SF_SAT_POLLS", build.chain_polls);
  if (build.chain_sum_all) options.define("SF_SAT_SUM_ALL", 1);
  cl::Program p = rt.program({"common.clh", "storage.clh", "vecio.clh", "sat_accum.clh", "sat.cl"}, options.str());
  // Every SAT kernel takes (src, W, H, band_rows, bands, scratch[, table]).
  auto kernel = [&](const char* name, int band_rows, int bands, bool with_table) {
    cl::Kernel k(p, name);
    detail::KernelArgs args(k);
    args.buffer(src).value(shape.width).value(shape.height).value(band_rows).value(bands).buffer(band_scratch);
    if (with_table) args.buffer(table);
    return k;
  };
  PassEvents ev;
  if (schedule == SatSchedule::Chained) {
    // The ticket counter and the statuses start at zero.
    rt.queue().enqueueFillBuffer(band_scratch, cl_int(0), L.chain_ctl_offset * sizeof(float),
                                 L.chain_ctl_ints * sizeof(cl_int), wait, &ev.first);
    EventList after{ev.first};
    rt.queue().enqueueNDRangeKernel(kernel("sf_sat_chain", L.chain_band_rows, L.chain_bands, true), cl::NullRange,
                                    cl::NDRange(size_t(L.chain_bands) * shape.channels), cl::NDRange(1), &after,
                                    &ev.last);
    return ev;
  }
  if (schedule == SatSchedule::PerChannel) {
    L.bands = 1;
    L.band_rows = shape.height;
  }
  // Nobody reads the last band's sums (one band has none to read).
  if (L.bands > 1)
    rt.queue().enqueueNDRangeKernel(kernel("sf_sat_bands", L.band_rows, L.bands, false), cl::NullRange,
                                    cl::NDRange((shape.width + kStrip - 1) / kStrip, L.bands - 1, shape.channels),
                                    cl::NDRange(1, 1, 1), wait, &ev.first);
  EventList after{ev.first};
  rt.queue().enqueueNDRangeKernel(kernel("sf_sat_rows", L.band_rows, L.bands, true), cl::NullRange,
                                  cl::NDRange(L.bands, shape.channels), cl::NDRange(1, 1), L.bands > 1 ? &after : wait,
                                  &ev.last);
  if (L.bands == 1) ev.first = ev.last;
  return ev;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_sat", e);
}

}  // namespace

cl::Event enqueue_sat(Runtime& rt, Storage storage, const SatBuild& build, const ScheduleOptions& schedule,
                      const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& table,
                      const cl::Buffer& band_scratch, cl::Event* first, const EventList* wait) {
  const PassEvents ev = sat_passes(rt, storage, src, table, band_scratch, shape, wait, build, schedule);
  if (first) *first = ev.first;
  return ev.last;
}

}  // namespace sf

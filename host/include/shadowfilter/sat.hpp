#pragma once
// Summed-area tables of basis images (methods.md sec. 3; docs/lookups.md; kernels/sat.cl);
// what a table holds within its error bound is sat_precision.hpp's. A thin typed wrapper in the argument order of
// device_types.hpp: buffers are the caller's, every call enqueues after `wait` and returns its last command's event.
#include "shadowfilter/device_types.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// Float-float table (hi + lo planes per channel) of (W+1) x (H+1) entries with zero first row
// and column; rows padded so that entries x >= 1 start on 64-byte lines (kernels/common.clh).
struct SatLayout {
  static constexpr int x0 = 15;              // SF_SAT_X0: where entry x = 0 lies in a row
  int bands = 1, band_rows = 1;              // row bands of the two-launch build
  int chain_bands = 1, chain_band_rows = 1;  // row bands of the one-launch build, per channel
  size_t chain_ctl_offset = 0;               // floats into the scratch: the one-launch build's control ints
  size_t chain_ctl_ints = 0;
  size_t pitch = 0;         // floats per table row: sf_sat_pitch(W), a multiple of 16 >= W + 16
  size_t plane_floats = 0;  // pitch (H+1)
  size_t table_floats = 0;  // 2 channels plane_floats
  size_t band_floats = 0;   // scratch for any schedule: up to 4 rows of W 8-byte entries per band
  // Index of S[y][x] of channel c in the table: hi plane, or lo with `lo`.
  size_t at(int c, bool lo, int x, int y) const {
    return (2 * size_t(c) + (lo ? 1 : 0)) * plane_floats + size_t(y) * pitch + x0 + size_t(x);
  }
};
SatLayout sat_layout(const ImageShape& shape);
// The build's accumulator (kernels/sat_accum.clh): double where the device has cl_khr_fp64,
// float-float otherwise; the same layout and bound to ~2^-44 either way.
enum class SatAccumulator { Auto, Double, FloatFloat };
// How the table is built (kernels/sat.cl); all give the same table.
//   PerChannel: one work-item per channel, one launch; the image read once.
//   Chained: bands of rows in one launch, each band taking the carries of the bands above as
//     they publish them; the image read once from memory (each band twice, the second from cache).
//   TwoLaunch: the column sums of every band, then the bands' rows; the image read twice.
//   WorkGroupScan (the Gpu family): a work-group per row scans it in blocks of its size in
//     local memory (the row prefixes, held in the table), then one work-item per column and
//     band adds them down, from the column sums of the bands above; the image read once.
// Auto: the family's default (ScheduleOptions::family, Auto = by device type): Gpu takes
// WorkGroupScan; Cpu takes PerChannel when the channels alone fill the compute units, else
// Chained on CPU devices and TwoLaunch elsewhere (sat_schedule).
enum class SatSchedule { Auto, PerChannel, Chained, TwoLaunch, WorkGroupScan };
SatSchedule sat_schedule(const Runtime& rt, const ImageShape& shape);
// How enqueue_sat builds the table; the defaults choose by device.
struct SatBuild {
  SatAccumulator accumulator = SatAccumulator::Auto;
  SatSchedule schedule = SatSchedule::Auto;
  // Chained: polls of a band's status before the band below sums that band's rows itself
  // (< 0: the kernel's ~1 ms); chain_sum_all: every band sums all the rows above it (tests).
  int chain_polls = -1;
  bool chain_sum_all = false;
};
// schedule: which family Auto takes (family) and WorkGroupScan's items per group
// (gpu_work_group: 0 for the table's 256; a power of two; smaller where the device allows fewer).
cl::Event enqueue_sat(Runtime& rt, Storage storage, const SatBuild& build, const ScheduleOptions& schedule,
                      const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& table,
                      const cl::Buffer& band_scratch, cl::Event* first = nullptr, const EventList* wait = nullptr);

}  // namespace sf

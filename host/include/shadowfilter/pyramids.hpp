#pragma once
// Pyramids, summed-area tables, footprint lookups and ESM failure classification
// (methods.md sec. 2-3; docs/lookups.md). Thin typed wrappers like kernels.hpp, in its argument
// order: buffers are the caller's, every call enqueues after `wait` and returns its last event.
#include <vector>

#include "shadowfilter/kernels.hpp"

namespace sf {

// --- mip pyramids -------------------------------------------------------------
// Level 0 is the caller's image; levels 1 .. top live one after the other in a "chain" buffer,
// each as `channels` planes of width x height values (kernels/pyramid.cl).
struct MipLevel {
  int width = 0, height = 0;
  size_t offset = 0;  // values from the start of the chain (levels >= 1; 0 for level 0)
};
struct MipLayout {
  int channels = 1;
  std::vector<MipLevel> levels;  // levels[0] = the full image
  size_t chain_values = 0;       // values in the chain (levels >= 1), 0 for a 1x1 image
  int top() const { return static_cast<int>(levels.size()) - 1; }
};
MipLayout mip_layout(int width, int height, int channels);

// Reduction of 2x2 texels: the mean for basis images, max / min for the z-max / z-min pyramids
// of the raw depth (conservative: every texel bounds the level-0 texels it covers).
enum class Reduce { Mean = 0, Max = 1, Min = 2 };

// Builds levels 1 .. top of `level0` (shape.channels planes in `storage`) into `chain` (at least
// mip_layout(...).chain_values values, never less than one). Two launches at most for maps up
// to 4096x4096 (32x32 tiles make five levels per launch; one work-item per channel finishes
// the levels of 128x128 and below).
// How the chain is built (docs/gpu.md, "Launch shapes"); every build gives the same max / min
// chains and mean chains within the storage's rounding. family Cpu: the 32x32 tiles (one item
// per four) and the per-channel tail; Gpu: work-groups of 16x16 items, one per texel of the next
// level, five levels per launch through local memory; Auto: by device type. The family and the
// items per Gpu group are ScheduleOptions::family and gpu_work_group (0: the table's 256; a power
// of two: the square below it, 8x8 for 64 or 128), as the blur and the SAT take them.
cl::Event enqueue_pyramid(Runtime& rt, Reduce op, Storage storage, const ScheduleOptions& schedule,
                          const ImageShape& shape, const cl::Buffer& level0, const cl::Buffer& chain,
                          cl::Event* first = nullptr, const EventList* wait = nullptr);

// --- summed-area tables -------------------------------------------------------
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

// --- lookups ------------------------------------------------------------------
// What a footprint lookup reads besides level 0 (empty buffers where not needed).
struct LookupBuffers {
  Lookup kind = Lookup::Bilinear;
  cl::Buffer chain;          // mips: the mip chain of the filtered basis
  cl::Buffer sat;            // sat: the summed-area table of the filtered basis
  cl::Buffer footprint;      // per receiver f in level-0 texels; empty = 1 everywhere
  cl::Buffer level_offsets;  // joined mips: mip_level_offsets (kernels.hpp); empty = built per call
};
// The shape.channels filtered values of `count` receivers (method-agnostic): out holds
// shape.channels planes of count floats. Used by tests and by callers with their own methods.
cl::Event enqueue_lookup_points(Runtime& rt, Storage storage, const ImageShape& shape, size_t count,
                                const LookupBuffers& lookup, const cl::Buffer& level0, const cl::Buffer& u,
                                const cl::Buffer& v, const cl::Buffer& out, const EventList* wait = nullptr);

// --- ESM failure classification (Annen 2008 ch. 7.3) ---------------------------
// Flags receivers whose lookup support may hold texels behind them (zmax: some texel z with
// z > d + offset, from the z-max pyramid; threshold: exp(-c d) bar(B) > 1 + eps) and replaces
// their visibility by a 2x2 PCF of the ESM test on the raw depth, against the receiver's plane
// (FilterOptions::receiver_plane; receiver_row as DeviceReceivers::row). flags: one uchar per
// receiver.
// `zmax_chain` is the Reduce::Max pyramid of `depth` (zmax mode only).
struct ClassifyInputs {
  cl::Buffer depth, zmax_chain;
  cl::Buffer basis;  // level 0 of the filtered basis (threshold mode)
  LookupBuffers lookup;
  int width = 0, height = 0;
};
cl::Event enqueue_esm_classify_points(Runtime& rt, const FilterOptions& opt, size_t count, int receiver_row,
                                      const ClassifyInputs& in, const cl::Buffer& u, const cl::Buffer& v,
                                      const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                      const EventList* wait = nullptr);
cl::Event enqueue_esm_classify_grid(Runtime& rt, const FilterOptions& opt, const ClassifyInputs& in,
                                    const cl::Buffer& d, const cl::Buffer& visibility, const cl::Buffer& flags,
                                    const EventList* wait = nullptr);
// The threshold eps in effect: opt.esm_classify.threshold_eps, or when negative the automatic
// exp(c offset)(1 + 1e-5) - 1, which makes threshold flag a subset of zmax (docs/lookups.md).
double esm_threshold_eps(const FilterOptions& opt);

}  // namespace sf

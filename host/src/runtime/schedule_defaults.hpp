#pragma once
// The launch shapes of the blur, the SAT and the pyramid per device type: one table
// (schedule_defaults.cpp), which ScheduleOptions::family and ::gpu_work_group override, and
// the fitting of a wanted work-group to what the device and the built kernel allow.
// docs/gpu.md, "Launch shapes".
#include <string>

#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// A work-group shape (work-items along x and y).
struct GroupShape {
  int x = 1, y = 1;
  int items() const { return x * y; }
};

// What one family launches (the Cpu family's own strip and band schedules are in blur.cpp and
// sat.cpp; its shapes here are the work-groups of one item they use).
struct LaunchDefaults {
  ScheduleFamily family = ScheduleFamily::Cpu;
  // blur: Cpu: one item per strip of 128 texels x up to 256 rows (blur.cpp, blur_schedule).
  //       Gpu: a work-group of 32 x 8 items, one per output texel and column, each computing
  //       `blur_rows_per_item` rows; its tile (8 x that rows plus the 2R halo) of row-blurred
  //       values lives in local memory.
  GroupShape blur_group;
  int blur_rows_per_item = 1;
  // sat: Cpu: SatSchedule Auto (sat_schedule: per channel, chained or two launches).
  //      Gpu: SatSchedule::WorkGroupScan: a work-group of `sat_group` items scans a row in
  //      blocks of as many texels in local memory, then one item per column and band adds down.
  int sat_group = 1;
  // pyramid: Cpu: 32x32 tiles, four side by side per item, and one item per channel for the
  //          small levels (pyramid.cpp). Gpu: work-groups of `pyramid_group`^2 items, one per
  //          texel of the next level, up to log2(pyramid_group) + 1 levels per launch through
  //          local memory.
  int pyramid_group = 1;
};

// The family a device type takes by default: "CPU" -> Cpu; "GPU", "accelerator" and anything
// else -> Gpu (work-groups of one item leave a GPU's lanes idle; an unknown device is more
// likely to want groups than a CPU is).
ScheduleFamily default_family(const std::string& device_type);
// `requested`, or for Auto the table's family for rt's device.
ScheduleFamily resolve_family(const Runtime& rt, ScheduleFamily requested);
// The table: the shapes of a family (Auto is not a family: InputError).
const LaunchDefaults& launch_defaults(ScheduleFamily family);

// Work-items per Gpu-family group: `override_items` (ScheduleOptions::gpu_work_group) when > 0,
// else `table_items`; refused unless a power of two in 1..1024 (InputError); then halved until
// it fits the device's CL_DEVICE_MAX_WORK_GROUP_SIZE.
int gpu_group_items(const Runtime& rt, int table_items, int override_items);
// The device's local memory in bytes (CL_DEVICE_LOCAL_MEM_SIZE).
size_t local_mem_bytes(const Runtime& rt);
// The most work-items per group a built kernel allows on rt's device (CL_KERNEL_WORK_GROUP_SIZE).
size_t kernel_group_limit(const Runtime& rt, const cl::Kernel& k);

}  // namespace sf

// The launch-shape defaults table (schedule_defaults.hpp; docs/gpu.md, "Launch shapes").
#include "schedule_defaults.hpp"

#include "shadowfilter/errors.hpp"

namespace sf {

const char* schedule_family_name(ScheduleFamily f) {
  switch (f) {
    case ScheduleFamily::Auto:
      return "auto";
    case ScheduleFamily::Cpu:
      return "cpu";
    case ScheduleFamily::Gpu:
      return "gpu";
  }
  return "?";
}

ScheduleFamily parse_schedule_family(const std::string& name) {
  if (name == "auto") return ScheduleFamily::Auto;
  if (name == "cpu") return ScheduleFamily::Cpu;
  if (name == "gpu") return ScheduleFamily::Gpu;
  throw InputError("schedule family must be auto, cpu or gpu, got '" + name + "'");
}

namespace {

// The table. Cpu: the PoCL-tuned schedules (work-groups of one item). Gpu: 256-item groups
// (8 warps of 32 or 4 wavefronts of 64: enough per group to hide a barrier, small enough that
// several groups stay resident per compute unit); the blur's 32-wide rows make each warp's
// loads and stores one or two 128-byte lines, its 8 rows x 4 rows per item a 32-row tile (the
// 2R halo rows are blurred along x twice, once per tile: 1 + 2R/32 of the work).
const LaunchDefaults kCpu{ScheduleFamily::Cpu, {1, 1}, 1, 1, 1};
const LaunchDefaults kGpu{ScheduleFamily::Gpu, {32, 8}, 4, 256, 16};

struct DeviceTypeEntry {
  const char* type;  // DeviceInfo::type
  ScheduleFamily family;
};
const DeviceTypeEntry kByDeviceType[] = {
    {"CPU", ScheduleFamily::Cpu},
    {"GPU", ScheduleFamily::Gpu},
    {"accelerator", ScheduleFamily::Gpu},
    {"other", ScheduleFamily::Gpu},
};

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

}  // namespace

ScheduleFamily default_family(const std::string& device_type) {
  for (const DeviceTypeEntry& e : kByDeviceType)
    if (device_type == e.type) return e.family;
  return ScheduleFamily::Gpu;
}

ScheduleFamily resolve_family(const Runtime& rt, ScheduleFamily requested) {
  return requested == ScheduleFamily::Auto ? default_family(rt.info().type) : requested;
}

const LaunchDefaults& launch_defaults(ScheduleFamily family) {
  if (family == ScheduleFamily::Cpu) return kCpu;
  if (family == ScheduleFamily::Gpu) return kGpu;
  throw InputError("launch_defaults: resolve ScheduleFamily::Auto first (resolve_family)");
}

int gpu_group_items(const Runtime& rt, int table_items, int override_items) {
  const int n = override_items > 0 ? override_items : table_items;
  if (override_items < 0 || !power_of_two(n) || n > 1024)
    throw InputError("ScheduleOptions::gpu_work_group must be 0 or a power of two in 1..1024, got " +
                     std::to_string(override_items));
  int items = n;
  const size_t device_max = rt.info().max_work_group_size;
  while (items > 1 && device_max > 0 && size_t(items) > device_max) items /= 2;
  return items;
}

size_t local_mem_bytes(const Runtime& rt) { return rt.device().getInfo<CL_DEVICE_LOCAL_MEM_SIZE>(); }

size_t kernel_group_limit(const Runtime& rt, const cl::Kernel& k) {
  return k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(rt.device());
}

}  // namespace sf

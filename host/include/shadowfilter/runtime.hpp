#pragma once
// OpenCL runtime: device choice, program building with an on-disk binary cache.
// A Runtime either creates its own context/queue (CLI, tests) or wraps a caller's.
#include "shadowfilter/opencl.hpp"

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sf {

struct DeviceInfo {
  int platform_index = 0;
  int device_index = 0;
  std::string platform_name;
  std::string device_name;
  std::string driver_version;
  std::string type;  // "GPU", "CPU", "accelerator", "other"
  cl_ulong global_mem_bytes = 0;
  cl_ulong max_alloc_bytes = 0;
  size_t max_work_group_size = 0;
  cl_uint compute_units = 0;
  bool fp64 = false;  // cl_khr_fp64 (the SAT accumulates in double where it can)
};

// Every OpenCL device on every platform, in platform/device order.
std::vector<DeviceInfo> list_devices();

class Runtime {
 public:
  // Picks a device: `selector` is "" (use $SHADOWFILTER_DEVICE, else first GPU, else first CPU),
  // "P:D" (platform P, device D), a plain index into list_devices(), "gpu", "cpu", or a
  // case-insensitive substring of the device name. Throws InputError when nothing matches.
  static std::shared_ptr<Runtime> create(const std::string& selector = "");

  // Wraps a caller's context and queue (the queue's device is used). Profiling is used for the
  // stage timings only if the caller's queue has CL_QUEUE_PROFILING_ENABLE.
  Runtime(cl::Context context, cl::CommandQueue queue);

  const cl::Context& context() const { return context_; }
  const cl::Device& device() const { return device_; }
  cl::CommandQueue& queue() { return queue_; }
  const DeviceInfo& info() const { return info_; }
  bool profiling() const { return profiling_; }

  // Treat the device as one without doubles (tests of the float-float paths every device without
  // cl_khr_fp64 takes): info().fp64 reads false and programs built from here on get
  // -DSF_NO_FP64. false restores what the device reports.
  void set_without_fp64(bool without);

  // OpenCL C compiler warnings about the library's own kernels (some drivers, PoCL among them,
  // print them to stderr while a program builds) are suppressed with -w: they say nothing about
  // the caller's input and would reach every user's terminal. On to see them: this, or
  // SHADOWFILTER_CL_WARNINGS=1 in the environment. Programs built from here on follow it.
  void set_compiler_warnings(bool on);
  // Where the warnings go while they are on: every program built from source with a non-empty
  // build log passes its kernel file names and the log here (the command's -v prints them).
  // Unset, the log stays with the driver. Programs loaded from the binary cache have no log.
  using BuildLogSink = std::function<void(const std::string& files, const std::string& log)>;
  void set_build_log_sink(BuildLogSink sink);
  // One-line notes about the runtime's housekeeping: a program cache entry that did not verify
  // (truncated, zeroed, of another build) and was discarded and rebuilt, or one that could not be
  // written. The command's -v prints them; unset, they are dropped (the run goes on either way).
  using NoticeSink = std::function<void(const std::string& note)>;
  void set_notice_sink(NoticeSink sink);

  // Builds (or fetches from the in-memory and disk caches) a program made of the named embedded
  // kernel files concatenated in order (e.g. {"common.clh", "methods/esm.clh", "transform.cl"}),
  // compiled with `options` (-D knobs). Throws DeviceError with the build log on failure.
  cl::Program program(const std::vector<std::string>& files, const std::string& options);

  // The directory of the on-disk program cache ($SHADOWFILTER_CACHE_DIR, else
  // $XDG_CACHE_HOME/shadowfilter, else ~/.cache/shadowfilter); empty string disables it.
  static std::string cache_dir();

 private:
  cl::Context context_;
  cl::Device device_;
  cl::CommandQueue queue_;
  DeviceInfo info_;
  bool device_fp64_ = false;  // what the device reports (info_.fp64 may be switched off)
  bool profiling_ = false;
  static bool compiler_warnings_from_env();
  bool compiler_warnings_ = compiler_warnings_from_env();
  BuildLogSink build_log_sink_;
  NoticeSink notice_sink_;
  std::mutex mutex_;
  std::map<std::string, cl::Program> programs_;  // key: file names and build options
};

// The source of one embedded kernel file (throws std::out_of_range for unknown names).
const std::string& kernel_source(const std::string& file);

// A sub-buffer of `parent` holding bytes [origin, origin + size): how a caller passes data that
// starts inside a larger buffer of its own to any function of the library. Throws InputError
// when the region does not lie in the parent or origin is not a multiple of the device's
// CL_DEVICE_MEM_BASE_ADDR_ALIGN (OpenCL's rule for sub-buffers).
cl::Buffer sub_buffer(const Runtime& rt, const cl::Buffer& parent, size_t origin, size_t size,
                      cl_mem_flags flags = CL_MEM_READ_WRITE);

// Seconds between an event's start and end (profiling queues), 0 otherwise.
double event_seconds(const cl::Event& e);
double event_seconds(const cl::Event& first, const cl::Event& last);

}  // namespace sf

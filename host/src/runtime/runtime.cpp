#include "shadowfilter/runtime.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "cl_errors.hpp"
#include "embedded_kernels.hpp"
#include "shadowfilter/methods.hpp"
#include "program_cache.hpp"
#include "shadowfilter/errors.hpp"

namespace sf {
namespace {

std::string device_type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

// The device's own properties (the platform fields are the caller's).
void describe_device(const cl::Device& d, DeviceInfo& i) {
  i.device_name = d.getInfo<CL_DEVICE_NAME>();
  i.driver_version = d.getInfo<CL_DRIVER_VERSION>();
  i.type = device_type_name(d.getInfo<CL_DEVICE_TYPE>());
  i.global_mem_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  i.max_alloc_bytes = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  i.max_work_group_size = d.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
  i.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
  i.fp64 = d.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
}

struct FoundDevice {
  DeviceInfo info;
  cl::Device device;
};

std::vector<FoundDevice> enumerate() {
  std::vector<FoundDevice> out;
  std::vector<cl::Platform> platforms;
  if (cl::Platform::get(&platforms) != CL_SUCCESS) return out;
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices
    }
    for (size_t d = 0; d < devices.size(); ++d) {
      DeviceInfo i;
      i.platform_index = static_cast<int>(p);
      i.device_index = static_cast<int>(d);
      i.platform_name = platforms[p].getInfo<CL_PLATFORM_NAME>();
      describe_device(devices[d], i);
      out.push_back({i, devices[d]});
    }
  }
  return out;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool is_number(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

const FoundDevice* select(const std::vector<FoundDevice>& all, const std::string& selector) {
  if (selector.empty()) {
    for (const auto& f : all)
      if (f.info.type == "GPU") return &f;
    for (const auto& f : all)
      if (f.info.type == "CPU") return &f;
    return all.empty() ? nullptr : &all.front();
  }
  const std::string s = lower(selector);
  if (s == "gpu" || s == "cpu") {
    for (const auto& f : all)
      if (lower(f.info.type) == s) return &f;
    return nullptr;
  }
  auto colon = s.find(':');
  if (colon != std::string::npos && is_number(s.substr(0, colon)) && is_number(s.substr(colon + 1))) {
    int p = std::stoi(s.substr(0, colon)), d = std::stoi(s.substr(colon + 1));
    for (const auto& f : all)
      if (f.info.platform_index == p && f.info.device_index == d) return &f;
    return nullptr;
  }
  if (is_number(s)) {
    size_t idx = std::stoul(s);
    return idx < all.size() ? &all[idx] : nullptr;
  }
  for (const auto& f : all)
    if (lower(f.info.device_name).find(s) != std::string::npos) return &f;
  return nullptr;
}

uint64_t fnv1a(const std::string& s, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string hex64(uint64_t v) {
  std::ostringstream o;
  o << std::hex;
  o.width(16);
  o.fill('0');
  o << v;
  return o.str();
}

std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

std::vector<DeviceInfo> list_devices() try {
  std::vector<DeviceInfo> out;
  for (auto& f : enumerate()) out.push_back(f.info);
  return out;
} catch (const cl::Error& e) {
  detail::throw_device_error("list_devices", e);
}

std::shared_ptr<Runtime> Runtime::create(const std::string& selector_arg) try {
  std::string selector = selector_arg;
  if (selector.empty()) {
    if (const char* env = std::getenv("SHADOWFILTER_DEVICE")) selector = env;
  }
  auto all = enumerate();
  if (all.empty()) throw InputError("no OpenCL device found (is an ICD such as pocl-opencl-icd installed?)");
  const FoundDevice* f = select(all, selector);
  if (!f) throw InputError("no OpenCL device matches '" + selector + "' (see `shadowfilter devices`)");
  cl::Context ctx(f->device);
  cl::CommandQueue q(ctx, f->device, CL_QUEUE_PROFILING_ENABLE);
  return std::make_shared<Runtime>(ctx, q);
} catch (const cl::Error& e) {
  detail::throw_device_error("Runtime::create", e);
}

Runtime::Runtime(cl::Context context, cl::CommandQueue queue) try
    : context_(std::move(context)), queue_(std::move(queue)) {
  device_ = queue_.getInfo<CL_QUEUE_DEVICE>();
  profiling_ = (queue_.getInfo<CL_QUEUE_PROPERTIES>() & CL_QUEUE_PROFILING_ENABLE) != 0;
  for (const auto& f : enumerate()) {
    if (f.device() == device_()) {
      info_ = f.info;
      break;
    }
  }
  if (info_.device_name.empty()) describe_device(device_, info_);  // not reachable by enumeration (sub-device, ...)
  device_fp64_ = info_.fp64;
} catch (const cl::Error& e) {
  detail::throw_device_error("Runtime::Runtime", e);
}

void Runtime::set_without_fp64(bool without) { info_.fp64 = device_fp64_ && !without; }

void Runtime::set_compiler_warnings(bool on) { compiler_warnings_ = on; }

void Runtime::set_build_log_sink(BuildLogSink sink) {
  std::lock_guard<std::mutex> lock(mutex_);
  build_log_sink_ = std::move(sink);
}

void Runtime::set_notice_sink(NoticeSink sink) {
  std::lock_guard<std::mutex> lock(mutex_);
  notice_sink_ = std::move(sink);
}

bool Runtime::compiler_warnings_from_env() {
  const char* v = std::getenv("SHADOWFILTER_CL_WARNINGS");
  return v && std::string(v) == "1";
}

std::string Runtime::cache_dir() {
  if (const char* d = std::getenv("SHADOWFILTER_CACHE_DIR")) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/shadowfilter";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/shadowfilter";
  return {};
}

namespace {

const std::map<std::string, std::string>& embedded_table() {
  static const std::map<std::string, std::string> table = [] {
    std::map<std::string, std::string> t;
    for (const auto& k : detail::embedded_kernels()) t.emplace(k.path, k.source);
    return t;
  }();
  return table;
}

}  // namespace

bool detail::has_embedded_kernel(const std::string& path) { return embedded_table().count(path) > 0; }

// The embedded files, then the headers that methods registered with their own source
// (MethodDesc::header_source, sf::register_method).
const std::string& kernel_source(const std::string& file) {
  const auto& table = embedded_table();
  if (auto it = table.find(file); it != table.end()) return it->second;
  for (const MethodDesc& m : methods())
    if (m.header == file && !m.header_source.empty()) return m.header_source;
  throw std::out_of_range("no embedded kernel file '" + file + "'");
}

cl::Program Runtime::program(const std::vector<std::string>& files, const std::string& base_options) try {
  const std::string options =
      base_options + (device_fp64_ && !info_.fp64 ? " -DSF_NO_FP64" : "") + (compiler_warnings_ ? "" : " -w");
  // Built programs are keyed by their file names and options, before any source is assembled:
  // the embedded sources cannot change within a process, so a hit costs one map lookup.
  std::string names;
  for (const auto& f : files) names += f + '\0';
  const std::string program_key = names + '\0' + options;
  std::lock_guard<std::mutex> lock(mutex_);
  if (auto it = programs_.find(program_key); it != programs_.end()) return it->second;

  // Every program starts with the types and constants the host shares (shared_types.clh).
  std::string source = "// ---- shared_types.clh\n" + kernel_source("shared_types.clh") + "\n";
  for (const auto& f : files) {
    source += "// ---- " + f + "\n";
    source += kernel_source(f);
    source += "\n";
  }
  // The binary cache outlives the process: its key is the source itself and the device.
  const std::string hash = hex64(fnv1a(source + '\0' + options + '\0' + info_.platform_name + '\0' + info_.device_name +
                                       '\0' + info_.driver_version));
  // The key an entry must carry: the hash with what it stands for, so that a file of another
  // build (a swapped or renamed entry) is told apart even before its checksum.
  const std::string key =
      hash + " " + info_.platform_name + " | " + info_.device_name + " | " + info_.driver_version + " | " + options;
  const std::string dir = cache_dir();
  const std::string cached = dir.empty() ? std::string() : (std::filesystem::path(dir) / (hash + ".bin")).string();
  if (!dir.empty()) {
    std::vector<unsigned char> binary;
    std::string problem;
    if (detail::read_cache_entry(cached, key, &binary, &problem)) {
      try {
        cl::Program p(context_, {device_}, cl::Program::Binaries{binary});
        p.build({device_}, options.c_str());
        programs_[program_key] = p;
        return p;
      } catch (const cl::Error& e) {
        problem = std::string("the driver refused it (") + e.what() + ")";
      }
    }
    if (!problem.empty()) {
      // Discarded and rebuilt from source below, which writes a good entry in its place.
      std::error_code ec;
      std::filesystem::remove(cached, ec);
      if (notice_sink_) notice_sink_("program cache: discarded " + cached + ": " + problem + "; rebuilt from source");
    }
  }

  std::string file_list;
  for (const auto& f : files) file_list += (file_list.empty() ? "" : " ") + f;
  cl::Program p(context_, source);
  try {
    p.build({device_}, options.c_str());
  } catch (const cl::Error&) {
    std::string log = p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    throw DeviceError("OpenCL build of [" + file_list + "] with '" + options + "' failed:\n" + one_line(log));
  }
  if (compiler_warnings_ && build_log_sink_) {
    const std::string log = p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    if (log.find_first_not_of(" \t\r\n") != std::string::npos) build_log_sink_(file_list, log);
  }
  if (!dir.empty()) {
    auto bins = p.getInfo<CL_PROGRAM_BINARIES>();
    if (!bins.empty() && !bins[0].empty()) {
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      const std::string problem = detail::write_cache_entry(cached, key, bins[0]);
      if (!problem.empty() && notice_sink_) notice_sink_("program cache: cannot write " + cached + ": " + problem);
    }
  }
  programs_[program_key] = p;
  return p;
} catch (const cl::Error& e) {
  detail::throw_device_error("Runtime::program", e);
}

cl::Buffer sub_buffer(const Runtime& rt, const cl::Buffer& parent, size_t origin, size_t size, cl_mem_flags flags) try {
  const size_t parent_size = parent.getInfo<CL_MEM_SIZE>();
  if (size == 0 || origin > parent_size || size > parent_size - origin)
    throw InputError("sub_buffer: bytes [" + std::to_string(origin) + ", " + std::to_string(origin + size) +
                     ") do not lie in a buffer of " + std::to_string(parent_size) + " bytes");
  const size_t align = rt.device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8;
  if (align > 0 && origin % align != 0)
    throw InputError("sub_buffer: origin " + std::to_string(origin) + " is not a multiple of " + std::to_string(align) +
                     " bytes, the device's CL_DEVICE_MEM_BASE_ADDR_ALIGN");
  cl_buffer_region region{origin, size};
  cl::Buffer p = parent;  // createSubBuffer is not const in opencl.hpp
  return p.createSubBuffer(flags, CL_BUFFER_CREATE_TYPE_REGION, &region);
} catch (const cl::Error& e) {
  detail::throw_device_error("sub_buffer", e);
}

double event_seconds(const cl::Event& e) { return event_seconds(e, e); }

double event_seconds(const cl::Event& first, const cl::Event& last) try {
  try {
    cl_ulong a = first.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    cl_ulong b = last.getProfilingInfo<CL_PROFILING_COMMAND_END>();
    return b > a ? (b - a) * 1e-9 : 0.0;
  } catch (const cl::Error&) {
    return 0.0;
  }
} catch (const cl::Error& e) {
  detail::throw_device_error("event_seconds", e);
}

}  // namespace sf

#pragma once
// The launch layer every kernel wrapper uses: program build options from one builder, kernel
// arguments set in kernel order by type (no argument indices in the wrappers), and the shared
// types' constants (kernels/shared_types.clh) checked against the host's enums.
#include <string>
#include <type_traits>
#include <vector>

#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"
#include "shared_types.clh"

namespace sf::detail {

static_assert(int(Storage::F32) == SF_STORAGE_F32 && int(Storage::F16) == SF_STORAGE_F16 &&
                  int(Storage::Unorm16) == SF_STORAGE_UNORM16 && int(Storage::Unorm8) == SF_STORAGE_UNORM8,
              "sf::Storage and SF_STORAGE_* must agree");
static_assert(int(Lookup::Bilinear) == SF_LOOKUP_BILINEAR && int(Lookup::Mips) == SF_LOOKUP_MIPS &&
                  int(Lookup::Sat) == SF_LOOKUP_SAT,
              "sf::Lookup and SF_LOOKUP_* must agree");
static_assert(int(EsmClassify::ZMax) == SF_CLASSIFY_ZMAX && int(EsmClassify::Threshold) == SF_CLASSIFY_THRESHOLD,
              "sf::EsmClassify and SF_CLASSIFY_* must agree");

// "-cl-std=CL1.2 -DNAME=VALUE ...": every program's options, in the order they are added (the
// order is part of the program cache's key, so one builder keeps equal programs equal).
class BuildOptions {
 public:
  BuildOptions() : s_("-cl-std=CL1.2") {}
  // Without -cl-std: options a caller adds to its own program's (embed.hpp).
  static BuildOptions without_standard() {
    BuildOptions b;
    b.s_.clear();
    return b;
  }
  BuildOptions& define(const std::string& name, const std::string& value) {
    s_ += (s_.empty() ? "-D" : " -D") + name + "=" + value;
    return *this;
  }
  BuildOptions& define(const std::string& name, int value) { return define(name, std::to_string(value)); }
  BuildOptions& flag(const std::string& name) {  // -DNAME
    s_ += (s_.empty() ? "-D" : " -D") + name;
    return *this;
  }
  BuildOptions& flag_if(bool on, const std::string& name) { return on ? flag(name) : *this; }
  BuildOptions& define_if(bool on, const std::string& name, int value) { return on ? define(name, value) : *this; }
  BuildOptions& storage(Storage s) { return define("SF_STORAGE", static_cast<int>(s)); }
  BuildOptions& lookup(Lookup l) { return define("SF_LOOKUP", static_cast<int>(l)); }
  // A program of one kernel of its file (common.clh, "One kernel per program"): the others are
  // compiled out, and a driver that loads the program from its binary reads only that kernel.
  BuildOptions& only_kernel(const std::string& name) { return flag("SF_ONE_KERNEL").flag("SF_ONLY_" + name); }
  BuildOptions& append(const std::string& options) {  // options another builder made (" -D...")
    const size_t first = options.find_first_not_of(' ');
    if (first != std::string::npos) s_ += (s_.empty() ? "" : " ") + options.substr(first);
    return *this;
  }
  const std::string& str() const { return s_; }

 private:
  std::string s_;
};

// The probes a footprint lookup reads at most (-DSF_ANISO, kernels/lookup.clh): the options'
// max_anisotropy where the lookup has a footprint and the receivers carry Jacobians, else 1
// (isotropic at f, no SF_ANISO).
inline int anisotropy(Lookup kind, const cl::Buffer& jacobian, int max_anisotropy) {
  return kind != Lookup::Bilinear && jacobian() ? max_anisotropy : 1;
}

// Sets a kernel's arguments in order: buffer() for __global pointers (optional() passes NULL
// for an empty buffer, which the kernel tests), value() for ints, floats and the shared structs,
// bytes() for parameters the registry packed.
class KernelArgs {
 public:
  explicit KernelArgs(cl::Kernel& k) : k_(k) {}
  KernelArgs& buffer(const cl::Buffer& b) {
    k_.setArg(i_++, b);
    return *this;
  }
  KernelArgs& optional(const cl::Buffer& b) {
    if (b())
      k_.setArg(i_++, b);
    else
      k_.setArg(i_++, sizeof(cl_mem), nullptr);
    return *this;
  }
  template <typename T>
  KernelArgs& value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T> && !std::is_pointer_v<T>, "by-value kernel arguments only");
    k_.setArg(i_++, sizeof(T), &v);
    return *this;
  }
  KernelArgs& bytes(const std::vector<uint8_t>& b) {
    k_.setArg(i_++, b.size(), b.data());
    return *this;
  }
  cl_uint count() const { return i_; }

 private:
  cl::Kernel& k_;
  cl_uint i_ = 0;
};

}  // namespace sf::detail

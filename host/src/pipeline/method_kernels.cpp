
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include "cl_errors.hpp"
#include "method_build.hpp"
#include "planned_scope.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf {

detail::BuildOptions& detail::add_method_options(BuildOptions& b, const MethodDesc& m, const FilterOptions& opt) {
  std::string id = m.name;
  std::replace(id.begin(), id.end(), '-', '_');
  return b.flag("SF_METHOD_" + id).storage(opt.storage).append(m.defines(opt));
}

std::string detail::method_build_options(const MethodDesc& m, const FilterOptions& opt) {
  BuildOptions b = BuildOptions::without_standard();
  return add_method_options(b, m, opt).str();
}

std::string detail::method_lookup_build_options(const MethodDesc& m, const FilterOptions& opt) {
  BuildOptions b = BuildOptions::without_standard();
  return add_method_options(b, m, opt).lookup(opt.lookup.kind).str();
}

int detail::reconstruct_vector_width(const FilterOptions& opt) {
  const int vec = opt.schedule.reconstruct_vector_width;
  if (vec != 1 && vec != 4 && vec != 8 && vec != 16)
    throw InputError("reconstruct vector width must be 1, 4, 8 or 16, got " + std::to_string(vec));
  return vec;
}

namespace {

size_t round_up(size_t n, size_t m) { return (n + m - 1) / m * m; }

cl::NDRange local_1d(const ScheduleOptions& s) {
  return s.work_group_size > 0 ? cl::NDRange(s.work_group_size) : cl::NullRange;
}
cl::NDRange global_1d(size_t n, const ScheduleOptions& s) {
  return cl::NDRange(s.work_group_size > 0 ? round_up(n, s.work_group_size) : n);
}

// A kernel of `file` built on the method's header, with the method's options and `extra`, in a
// program of that kernel alone (BuildOptions::only_kernel).
cl::Kernel method_kernel(Runtime& rt, const MethodDesc& m, const FilterOptions& opt, const char* file, const char* name,
                         const detail::BuildOptions& extra = detail::BuildOptions::without_standard()) {
  detail::BuildOptions b;
  detail::add_method_options(b, m, opt).append(extra.str()).only_kernel(name);
  cl::Program p = rt.program({"common.clh", "storage.clh", m.header, "lookup.clh", file}, b.str());
  return cl::Kernel(p, name);
}

// The method's sf_method_params for these options, validated.
std::vector<uint8_t> method_params(const MethodDesc& m, const FilterOptions& opt) {
  detail::validate_unless_planned(m, opt);
  return m.pack_params(opt);
}

}  // namespace

cl::Event enqueue_transform(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width, int height,
                            const cl::Buffer& depth, const cl::Buffer& basis, const EventList* wait) try {
  const int texels = width * height;
  if (method.raw_depth) {  // sm, pcf: the "basis" is the depth map itself
    detail::validate_unless_planned(method, opt);
    cl::Event e;
    rt.queue().enqueueCopyBuffer(depth, basis, 0, 0, size_t(texels) * sizeof(float), wait, &e);
    return e;
  }
  // SF_XVEC texels per work-item in explicit vectors (transform.cl: sf_transformv), or one texel
  // per work-item (sf_transform).
  const int vec = opt.schedule.transform_vector_width;
  if (vec != 1 && vec != 4 && vec != 8 && vec != 16)
    throw InputError("transform vector width must be 1, 4, 8 or 16, got " + std::to_string(vec));
  // Vectors per work-item of sf_transformv (SF_XREP, why in transform.cl): with more than 4
  // planes, one whole 64-byte line of every plane per item.
  const int rep = method.channels(opt) > 4 ? std::max(1, 64 / (vec * storage_bytes(opt.storage))) : 1;
  cl::Kernel k =
      vec == 1 ? method_kernel(rt, method, opt, "transform.cl", "sf_transform")
               : method_kernel(rt, method, opt, "transform.cl", "sf_transformv",
                               detail::BuildOptions::without_standard().define("SF_XVEC", vec).define("SF_XREP", rep));
  detail::KernelArgs(k).buffer(depth).buffer(basis).value(texels).value(texels).bytes(method_params(method, opt));
  cl::Event e;
  // sf_transformv: work-groups of 64 items unless the schedule fixes one. PoCL gives a private
  // basis array it does not keep in registers (csm M = 32: 64 vectors) one copy per work-item of
  // the group on the thread's stack; its own choice (up to 4096 items) overflowed it. 64 is as
  // fast as PoCL's choice for the other methods.
  ScheduleOptions sched = opt.schedule;
  if (vec > 1 && sched.work_group_size == 0) sched.work_group_size = 64;
  const size_t per_item = size_t(vec) * (vec > 1 ? rep : 1);
  const size_t items = (size_t(texels) + per_item - 1) / per_item;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global_1d(items, sched), local_1d(sched), wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_transform", e);
}

namespace {

// The element offset of `chain` in `basis` when chain is a sub-buffer of basis (the pipeline's
// joined mip layout: level 0 at 0, the chain after it, then one padding value that the pair
// loads of the last texel read) and every index fits an int; else -1.
int joined_chain_offset(const cl::Buffer& basis, const cl::Buffer& chain, size_t bytes, size_t chain_values) {
  if (!chain() || !basis()) return -1;
  if (chain.getInfo<CL_MEM_ASSOCIATED_MEMOBJECT>()() != basis()) return -1;
  const size_t offset = chain.getInfo<CL_MEM_OFFSET>();
  const size_t size = chain.getInfo<CL_MEM_SIZE>();
  if (offset % bytes != 0 || size < (chain_values + 1) * bytes ||
      (offset + size) / bytes > size_t(std::numeric_limits<int>::max()))
    return -1;
  return static_cast<int>(offset / bytes);
}

// Level k's element offset in the joined buffer, k = 0 .. top (the kernel's level_offsets).
cl::Buffer level_offset_table(Runtime& rt, const MipLayout& mips, int chain_offset) {
  std::vector<cl_int> offsets{0};
  for (int l = 1; l <= mips.top(); ++l) offsets.push_back(chain_offset + static_cast<cl_int>(mips.levels[l].offset));
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, offsets.size() * sizeof(cl_int),
                    offsets.data());
}

}  // namespace

cl::Buffer mip_level_offsets(Runtime& rt, Storage storage, const cl::Buffer& basis, const cl::Buffer& chain,
                             const ImageShape& shape) try {
  const MipLayout mips = mip_layout(shape.width, shape.height, shape.channels);
  const int chain_offset = joined_chain_offset(basis, chain, storage_bytes(storage), mips.chain_values);
  return chain_offset >= 0 ? level_offset_table(rt, mips, chain_offset) : cl::Buffer();
} catch (const cl::Error& e) {
  detail::throw_device_error("mip_level_offsets", e);
}

cl::Event enqueue_reconstruct_points(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width,
                                     int height, size_t count, int receiver_row, const cl::Buffer& basis,
                                     const LookupBuffers* lookup, const cl::Buffer& u, const cl::Buffer& v,
                                     const cl::Buffer& d, const cl::Buffer& visibility, const EventList* wait) try {
  if (method.raw_depth)
    return enqueue_pcf_points(rt, opt, width, height, count, receiver_row, basis, u, v, d,
                              lookup ? lookup->footprint : cl::Buffer(), lookup ? lookup->jacobian : cl::Buffer(),
                              visibility, wait);
  // The footprint lookup (lookup.hpp): -DSF_LOOKUP and its buffers, null when unused.
  const Lookup kind = lookup ? lookup->kind : Lookup::Bilinear;
  int vec = detail::reconstruct_vector_width(opt);
  // At most 64 basis values per lookup and work-item: wider (csm M >= 16 at width 16, mips)
  // overflowed PoCL's work-item stack. Only csm narrows (M = 8: width 4; M >= 16: width 1);
  // every width gives the same values (tests/core/test_reconstruct_vec.cpp).
  while (vec > 1 && method.channels(opt) * vec > 64) vec = vec == 4 ? 1 : vec / 2;
  const MipLayout mips = kind == Lookup::Mips ? mip_layout(width, height, method.channels(opt)) : MipLayout{};
  const int chain_offset =
      kind == Lookup::Mips ? joined_chain_offset(basis, lookup->chain, storage_bytes(opt.storage), mips.chain_values)
                           : -1;
  const bool joined = chain_offset >= 0;
  const int aniso = lookup ? detail::anisotropy(kind, lookup->jacobian, lookup->max_anisotropy) : 1;
  cl::Kernel k = method_kernel(
      rt, method, opt, "reconstruct.cl", "sf_reconstruct_points",
      detail::BuildOptions::without_standard()
          .define("SF_RX_VEC", vec)
          .append(kind == Lookup::Bilinear ? "" : detail::BuildOptions::without_standard().lookup(kind).str())
          .flag_if(joined, "SF_MIPS_JOINED")
          .define_if(aniso > 1, "SF_ANISO", aniso)
          .flag_if(joined || (kind == Lookup::Bilinear && width >= 2), "SF_RX_PAIRS"));
  // The caller's table (the pipeline builds it once with its mip chain), else one built here.
  cl::Buffer level_offsets = joined ? lookup->level_offsets : cl::Buffer();
  if (joined) {
    const size_t table_bytes = size_t(mips.top() + 1) * sizeof(cl_int);
    if (!level_offsets())
      level_offsets = level_offset_table(rt, mips, chain_offset);
    else if (level_offsets.getInfo<CL_MEM_SIZE>() != table_bytes)
      throw InputError("mips level_offsets holds " + std::to_string(level_offsets.getInfo<CL_MEM_SIZE>()) +
                       " bytes, the chain needs " + std::to_string(table_bytes));
  }
  const cl::Buffer none;
  detail::KernelArgs(k)
      .buffer(basis)
      .value(width)
      .value(height)
      .value(width * height)
      .buffer(u)
      .buffer(v)
      .buffer(d)
      .buffer(visibility)
      .value(static_cast<int>(count))
      .bytes(method_params(method, opt))
      .optional(kind == Lookup::Mips ? lookup->chain : none)
      .optional(kind == Lookup::Sat ? lookup->sat : none)
      .optional(aniso > 1 ? lookup->jacobian
                : lookup  ? lookup->footprint
                          : none)
      .optional(level_offsets);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global_1d((count + vec - 1) / vec, opt.schedule),
                                  local_1d(opt.schedule), wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_reconstruct_points", e);
}

cl::Event enqueue_reconstruct_grid(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width,
                                   int height, const cl::Buffer& basis, const cl::Buffer& d,
                                   const cl::Buffer& visibility, const EventList* wait) try {
  if (method.raw_depth) return enqueue_pcf_grid(rt, opt, width, height, basis, d, visibility, wait);
  cl::Kernel k = method_kernel(rt, method, opt, "reconstruct.cl", "sf_reconstruct_grid");
  detail::KernelArgs(k)
      .buffer(basis)
      .value(width)
      .value(height)
      .value(width * height)
      .buffer(d)
      .buffer(visibility)
      .bytes(method_params(method, opt));
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(width, height), cl::NullRange, wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_reconstruct_grid", e);
}

}  // namespace sf

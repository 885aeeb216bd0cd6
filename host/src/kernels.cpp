#include "shadowfilter/kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "cl_errors.hpp"
#include "method_build.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf {

std::string detail::method_build_options(const MethodDesc& m, const FilterOptions& opt) {
  std::string id = m.name;
  std::replace(id.begin(), id.end(), '-', '_');
  return "-DSF_METHOD_" + id + " -DSF_STORAGE=" + std::to_string(static_cast<int>(opt.storage)) +
         m.defines(opt);
}

std::string detail::method_lookup_build_options(const MethodDesc& m, const FilterOptions& opt) {
  return method_build_options(m, opt) + " -DSF_LOOKUP=" + std::to_string(static_cast<int>(opt.lookup.kind));
}

namespace {

size_t round_up(size_t n, size_t m) { return (n + m - 1) / m * m; }

cl::NDRange local_1d(const ScheduleOptions& s) {
  return s.work_group_size > 0 ? cl::NDRange(s.work_group_size) : cl::NullRange;
}
cl::NDRange global_1d(size_t n, const ScheduleOptions& s) {
  return cl::NDRange(s.work_group_size > 0 ? round_up(n, s.work_group_size) : n);
}

std::string method_options(const MethodDesc& m, const FilterOptions& opt) {
  return "-cl-std=CL1.2 " + detail::method_build_options(m, opt);
}

cl::Kernel method_kernel(Runtime& rt, const MethodDesc& m, const FilterOptions& opt,
                         const char* file, const char* name, const std::string& extra = "") {
  cl::Program p = rt.program({"common.clh", "storage.clh", m.header, "lookup.clh", file},
                             method_options(m, opt) + extra);
  return cl::Kernel(p, name);
}

void set_params(cl::Kernel& k, cl_uint index, const MethodDesc& m, const FilterOptions& opt) {
  m.validate(opt);
  auto bytes = m.pack_params(opt);
  k.setArg(index, bytes.size(), bytes.data());
}

}  // namespace

float default_blur_sigma(int radius) { return (2.0f * radius + 1.0f) / 6.0f; }

std::vector<float> gaussian_weights(int radius, float sigma) {
  if (radius < 0 || radius > kMaxBlurRadius)
    throw InputError("FilterOptions::blur.radius must be in 0.." + std::to_string(kMaxBlurRadius) + ", got " +
                     std::to_string(radius));
  if (!std::isfinite(sigma))
    throw InputError("FilterOptions::blur.sigma must be a finite number (<= 0: the default (2R+1)/6), got " +
                     std::to_string(sigma));
  if (sigma <= 0.0f) sigma = default_blur_sigma(radius);
  std::vector<double> w(radius + 1);
  double sum = 0.0;
  for (int k = 0; k <= radius; ++k) {
    w[k] = std::exp(-double(k) * k / (2.0 * double(sigma) * sigma));
    sum += (k == 0 ? 1.0 : 2.0) * w[k];
  }
  std::vector<float> out(radius + 1);
  for (int k = 0; k <= radius; ++k) out[k] = static_cast<float>(w[k] / sum);
  return out;
}

cl::Event enqueue_transform(Runtime& rt, const MethodDesc& method, const FilterOptions& opt,
                            const cl::Buffer& depth, int width, int height, const cl::Buffer& basis,
                            const EventList* wait) try {
  const int texels = width * height;
  if (method.raw_depth) {  // sm, pcf: the "basis" is the depth map itself
    method.validate(opt);
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
  cl::Kernel k = vec == 1 ? method_kernel(rt, method, opt, "transform.cl", "sf_transform")
                          : method_kernel(rt, method, opt, "transform.cl", "sf_transformv",
                                          " -DSF_XVEC=" + std::to_string(vec) +
                                              " -DSF_XREP=" + std::to_string(rep));
  k.setArg(0, depth);
  k.setArg(1, basis);
  k.setArg(2, texels);
  k.setArg(3, texels);
  set_params(k, 4, method, opt);
  cl::Event e;
  // sf_transformv: work-groups of 64 items unless the schedule fixes one. PoCL gives a private
  // basis array it does not keep in registers (csm M = 32: 64 vectors) one copy per work-item of
  // the group on the thread's stack; its own choice (up to 4096 items) overflowed it. 64 is as
  // fast as PoCL's choice for the other methods.
  ScheduleOptions sched = opt.schedule;
  if (vec > 1 && sched.work_group_size == 0) sched.work_group_size = 64;
  const size_t per_item = size_t(vec) * (vec > 1 ? rep : 1);
  const size_t items = (size_t(texels) + per_item - 1) / per_item;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global_1d(items, sched), local_1d(sched), wait,
                                  &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_transform", e);
}

namespace {

// The fused blur's schedule (blur.cl: SF_VEC, SF_STRIP, SF_ROWS, SF_STREAM); none of it changes
// a result.
struct BlurSchedule {
  int vec = 16;         // texels per vector
  int strip = 1;        // vectors per work-item along a row
  int rows = 64;        // output rows per work-item
  bool stream = false;  // streaming stores: every row starts on a vector boundary
};
constexpr int kBlurStepRows = 4;     // SF_VROWS: output rows per step, sharing their ring loads
constexpr int kBlurCopyChunk = 4096;  // SF_COPY_CHUNK: floats per work-item of sf_blur_copy

int floor_pow2(int n) {
  int p = 1;
  while (p <= n / 2) p *= 2;
  return p;
}

int ceil_div(int a, int b) { return (a + b - 1) / b; }

// Strip: 128 texels (64 once the private ring, two copies of 2R + 4 strip rows, would pass
// 128 KiB). Rows: 256, fewer when needed to give every compute unit 8 work-items; long strips
// make the 2R halo rows that two work-items both blur along x a small share. Measured on PoCL
// (2 cores, AVX-512): 128 x 256 is within noise of the best of {64, 128, 256}^2 for R = 1..31.
BlurSchedule blur_schedule(const Runtime& rt, int radius, const ScheduleOptions& sched,
                           const ImageShape& shape) {
  BlurSchedule s;
  s.vec = sched.blur_vector_width;
  const int span = 2 * radius + kBlurStepRows;
  const int texels = sched.blur_strip_texels > 0 ? sched.blur_strip_texels
                                                 : std::clamp(floor_pow2(16384 / span), 64, 128);
  s.strip = std::max(1, texels / s.vec);
  if (sched.blur_rows > 0) {
    s.rows = sched.blur_rows;
  } else {
    s.rows = 256;
    const int strips = ceil_div(shape.width, s.strip * s.vec) * shape.channels;
    const int wanted = 8 * static_cast<int>(std::max<cl_uint>(rt.info().compute_units, 1));
    while (s.rows > 16 && strips * ceil_div(shape.height, s.rows) < wanted) s.rows /= 2;
  }
  s.stream = shape.width % s.vec == 0;
  return s;
}

// The blur's compile-time constants: radius, the weights as exact hex-float literals, schedule.
std::string blur_build_options(const BlurOptions& blur, const BlurSchedule& s, Storage storage) {
  std::string weights;
  for (float w : gaussian_weights(blur.radius, blur.sigma)) {
    char lit[32];
    std::snprintf(lit, sizeof lit, "%af", w);
    weights += (weights.empty() ? "" : ",") + std::string(lit);
  }
  return "-cl-std=CL1.2 -DSF_RADIUS=" + std::to_string(blur.radius) + " -DSF_WEIGHTS=" + weights +
         " -DSF_VEC=" + std::to_string(s.vec) + " -DSF_STRIP=" + std::to_string(s.strip) +
         " -DSF_ROWS=" + std::to_string(s.rows) + " -DSF_VROWS=" + std::to_string(kBlurStepRows) +
         " -DSF_STORAGE=" + std::to_string(static_cast<int>(storage)) + (s.stream ? " -DSF_STREAM" : "");
}

// The copy back of an in-place blur, tmp -> dst, after `blurred` (blur.cl: sf_blur_copy).
cl::Event enqueue_copy_back(Runtime& rt, const cl::Program& p, const cl::Buffer& tmp,
                            const cl::Buffer& dst, const ImageShape& shape,
                            const cl::Event& blurred) {
  cl::Kernel copy(p, "sf_blur_copy");
  const int count = static_cast<int>(shape.plane_texels() * shape.channels);
  copy.setArg(0, tmp);
  copy.setArg(1, dst);
  copy.setArg(2, count);
  const EventList after{blurred};
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(copy, cl::NullRange, cl::NDRange(ceil_div(count, kBlurCopyChunk)),
                                  cl::NDRange(1), &after, &e);
  return e;
}

}  // namespace

BlurEvents enqueue_blur(Runtime& rt, const BlurOptions& blur, const ScheduleOptions& sched,
                        const cl::Buffer& src, const cl::Buffer& tmp, const cl::Buffer& dst,
                        const ImageShape& shape, const EventList* wait, Storage storage) try {
  BlurEvents ev;
  if (blur.radius == 0) {
    if (src() != dst()) {
      rt.queue().enqueueCopyBuffer(src, dst, 0, 0, shape.bytes(), wait, &ev.rows);
    } else {
      rt.queue().enqueueMarkerWithWaitList(wait, &ev.rows);
    }
    ev.cols = ev.rows;
    return ev;
  }
  const int vec = sched.blur_vector_width;
  if (vec != 4 && vec != 8 && vec != 16)
    throw InputError("blur vector width must be 4, 8 or 16, got " + std::to_string(vec));
  if (sched.blur_strip_texels < 0 || sched.blur_strip_texels % vec != 0 || sched.blur_rows < 0)
    throw InputError("blur strip must be a multiple of the vector width and rows >= 0");
  if (shape.value_bytes != storage_bytes(storage))
    throw InputError(std::string("blur: the image holds ") + std::to_string(shape.value_bytes) +
                     "-byte values, storage " + storage_name(storage) + " has " +
                     std::to_string(storage_bytes(storage)));
  // Both passes run in one kernel, which cannot blur in place: in place goes through tmp and a
  // copy back.
  const bool in_place = src() == dst();
  const BlurSchedule s = blur_schedule(rt, blur.radius, sched, shape);
  const cl::Program p =
      rt.program({"common.clh", "storage.clh", "blur.cl"}, blur_build_options(blur, s, storage));
  cl::Kernel k(p, "sf_blur");
  k.setArg(0, src);
  k.setArg(1, in_place ? tmp : dst);
  k.setArg(2, shape.width);
  k.setArg(3, shape.height);
  k.setArg(4, static_cast<int>(shape.plane_texels()));
  const cl::NDRange global(ceil_div(shape.width, s.strip * s.vec), ceil_div(shape.height, s.rows),
                           shape.channels);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global, cl::NDRange(1, 1, 1), wait, &ev.rows);
  ev.cols = in_place ? enqueue_copy_back(rt, p, tmp, dst, shape, ev.rows) : ev.rows;
  return ev;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_blur", e);
}

namespace {

// The element offset of `chain` in `basis` when chain is a sub-buffer of basis (the pipeline's
// joined mip layout: level 0 at 0, the chain after it, then one padding value that the pair
// loads of the last texel read) and every index fits an int; else -1.
int joined_chain_offset(const cl::Buffer& basis, const cl::Buffer& chain, size_t bytes,
                        size_t chain_values) {
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
  for (int l = 1; l <= mips.top(); ++l)
    offsets.push_back(chain_offset + static_cast<cl_int>(mips.levels[l].offset));
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                    offsets.size() * sizeof(cl_int), offsets.data());
}

}  // namespace

cl::Buffer mip_level_offsets(Runtime& rt, Storage storage, const cl::Buffer& basis,
                             const cl::Buffer& chain, const ImageShape& shape) try {
  const MipLayout mips = mip_layout(shape.width, shape.height, shape.channels);
  const int chain_offset = joined_chain_offset(basis, chain, storage_bytes(storage), mips.chain_values);
  return chain_offset >= 0 ? level_offset_table(rt, mips, chain_offset) : cl::Buffer();
} catch (const cl::Error& e) {
  detail::throw_device_error("mip_level_offsets", e);
}

cl::Event enqueue_reconstruct_points(Runtime& rt, const MethodDesc& method, const FilterOptions& opt,
                                     const cl::Buffer& basis, int width, int height,
                                     const cl::Buffer& u, const cl::Buffer& v, const cl::Buffer& d,
                                     const cl::Buffer& visibility, size_t count,
                                     const EventList* wait, const LookupBuffers* lookup) try {
  if (method.raw_depth)
    return enqueue_pcf_points(rt, opt, basis, width, height, u, v, d, visibility, count, wait,
                              lookup ? &lookup->footprint : nullptr);
  // The footprint lookup (pyramids.hpp): -DSF_LOOKUP and its buffers, null when unused.
  const Lookup kind = lookup ? lookup->kind : Lookup::Bilinear;
  int vec = opt.schedule.reconstruct_vector_width;
  if (vec != 1 && vec != 4 && vec != 8 && vec != 16)
    throw InputError("reconstruct vector width must be 1, 4, 8 or 16, got " + std::to_string(vec));
  // At most 64 basis values per lookup and work-item: wider (csm M >= 16 at width 16, mips)
  // overflowed PoCL's work-item stack. Only csm narrows (M = 8: width 4; M >= 16: width 1);
  // every width gives the same values (tests/test_reconstruct_vec.cpp).
  while (vec > 1 && method.channels(opt) * vec > 64) vec = vec == 4 ? 1 : vec / 2;
  const MipLayout mips = kind == Lookup::Mips ? mip_layout(width, height, method.channels(opt)) : MipLayout{};
  const int chain_offset = kind == Lookup::Mips ? joined_chain_offset(basis, lookup->chain,
                                                                     storage_bytes(opt.storage),
                                                                     mips.chain_values)
                                                : -1;
  cl::Kernel k = method_kernel(rt, method, opt, "reconstruct.cl", "sf_reconstruct_points",
                               " -DSF_RX_VEC=" + std::to_string(vec) +
                                   (kind == Lookup::Bilinear
                                        ? std::string()
                                        : " -DSF_LOOKUP=" + std::to_string(static_cast<int>(kind))) +
                                   (chain_offset >= 0 ? " -DSF_MIPS_JOINED" : "") +
                                   (chain_offset >= 0 || (kind == Lookup::Bilinear && width >= 2)
                                        ? " -DSF_RX_PAIRS"
                                        : ""));
  // The caller's table (the pipeline builds it once with its mip chain), else one built here.
  cl::Buffer level_offsets = chain_offset >= 0 ? lookup->level_offsets : cl::Buffer();
  if (chain_offset >= 0) {
    const size_t table_bytes = size_t(mips.top() + 1) * sizeof(cl_int);
    if (!level_offsets())
      level_offsets = level_offset_table(rt, mips, chain_offset);
    else if (level_offsets.getInfo<CL_MEM_SIZE>() != table_bytes)
      throw InputError("mips level_offsets holds " + std::to_string(level_offsets.getInfo<CL_MEM_SIZE>()) +
                       " bytes, the chain needs " + std::to_string(table_bytes));
    k.setArg(13, level_offsets);
  } else {
    k.setArg(13, sizeof(cl_mem), nullptr);
  }
  auto buffer_or_null = [&k](cl_uint i, const cl::Buffer* b) {
    if (b && (*b)())
      k.setArg(i, *b);
    else
      k.setArg(i, sizeof(cl_mem), nullptr);
  };
  buffer_or_null(10, kind == Lookup::Mips ? &lookup->chain : nullptr);
  buffer_or_null(11, kind == Lookup::Sat ? &lookup->sat : nullptr);
  buffer_or_null(12, lookup ? &lookup->footprint : nullptr);
  k.setArg(0, basis);
  k.setArg(1, width);
  k.setArg(2, height);
  k.setArg(3, width * height);
  k.setArg(4, u);
  k.setArg(5, v);
  k.setArg(6, d);
  k.setArg(7, visibility);
  k.setArg(8, static_cast<int>(count));
  set_params(k, 9, method, opt);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global_1d((count + vec - 1) / vec, opt.schedule),
                                  local_1d(opt.schedule), wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_reconstruct_points", e);
}

cl::Event enqueue_reconstruct_grid(Runtime& rt, const MethodDesc& method, const FilterOptions& opt,
                                   const cl::Buffer& basis, int width, int height,
                                   const cl::Buffer& d, const cl::Buffer& visibility,
                                   const EventList* wait) try {
  if (method.raw_depth) return enqueue_pcf_grid(rt, opt, basis, width, height, d, visibility, wait);
  cl::Kernel k = method_kernel(rt, method, opt, "reconstruct.cl", "sf_reconstruct_grid");
  k.setArg(0, basis);
  k.setArg(1, width);
  k.setArg(2, height);
  k.setArg(3, width * height);
  k.setArg(4, d);
  k.setArg(5, visibility);
  set_params(k, 6, method, opt);
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(width, height), cl::NullRange, wait,
                                  &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_reconstruct_grid", e);
}

}  // namespace sf

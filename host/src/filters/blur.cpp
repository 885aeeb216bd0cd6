// The separable Gaussian prefilter (kernels/blur.cl): its weights, its schedule and its launch.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "schedule_defaults.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/blur.hpp"

namespace sf {

float default_blur_sigma(int radius) { return (2.0f * radius + 1.0f) / 6.0f; }

namespace {
void check_radius(int radius) {
  if (radius < 0 || radius > kMaxBlurRadius)
    throw InputError("FilterOptions::blur.radius must be in 0.." + std::to_string(kMaxBlurRadius) + ", got " +
                     std::to_string(radius));
}
}  // namespace

std::vector<float> gaussian_weights(int radius, float sigma) {
  check_radius(radius);
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

namespace {

// The fused blur's schedule (blur.cl: SF_VEC, SF_STRIP, SF_ROWS, SF_STREAM); none of it changes
// a result.
struct BlurSchedule {
  int vec = 16;         // texels per vector
  int strip = 1;        // vectors per work-item along a row
  int rows = 64;        // output rows per work-item
  bool stream = false;  // streaming stores: every row starts on a vector boundary
};
constexpr int kBlurStepRows = 4;      // SF_VROWS: output rows per step, sharing their ring loads
constexpr int kBlurCopyChunk = 4096;  // SF_COPY_CHUNK: floats per work-item of sf_blur_copy

int floor_pow2(int n) {
  int p = 1;
  while (p <= n / 2) p *= 2;
  return p;
}

int ceil_div(int a, int b) { return (a + b - 1) / b; }

// Strip: 128 texels (64 once the private ring, two copies of 2R + 4 strip rows, would pass
// 128 KiB). Rows: 256, fewer when needed to give every compute unit 8 work-items; long strips
// make the 2R halo rows that two work-items both blur along x a small share (the measurement
// against other tiles: docs/lookups.md "The blur's CPU schedule").
BlurSchedule blur_schedule(const Runtime& rt, int radius, const ScheduleOptions& sched, const ImageShape& shape) {
  BlurSchedule s;
  s.vec = sched.blur_vector_width;
  const int span = 2 * radius + kBlurStepRows;
  const int texels =
      sched.blur_strip_texels > 0 ? sched.blur_strip_texels : std::clamp(floor_pow2(16384 / span), 64, 128);
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

// The weights as exact hex-float literals, comma-separated (SF_WEIGHTS).
std::string weight_literals(const BlurOptions& blur) {
  std::string weights;
  for (float w : gaussian_weights(blur.radius, blur.sigma)) {
    char lit[32];
    std::snprintf(lit, sizeof lit, "%af", w);
    weights += (weights.empty() ? "" : ",") + std::string(lit);
  }
  return weights;
}

// What the separable kernels sum or take the max of: the Gaussian's weights, or SF_BLUR_MAX.
detail::BuildOptions& add_taps(detail::BuildOptions& b, const BlurOptions& blur, bool max_filter) {
  b.define("SF_RADIUS", blur.radius);
  return max_filter ? b.flag("SF_BLUR_MAX") : b.define("SF_WEIGHTS", weight_literals(blur));
}

// The blur's compile-time constants: radius, the weights, schedule.
std::string blur_build_options(const BlurOptions& blur, bool max_filter, const BlurSchedule& s, Storage storage) {
  detail::BuildOptions b;
  return add_taps(b, blur, max_filter)
      .define("SF_VEC", s.vec)
      .define("SF_STRIP", s.strip)
      .define("SF_ROWS", s.rows)
      .define("SF_VROWS", kBlurStepRows)
      .storage(storage)
      .flag_if(s.stream, "SF_STREAM")
      .str();
}

// The copy back of an in-place blur, tmp -> dst, after `blurred` (blur.cl: sf_blur_copy).
cl::Event enqueue_copy_back(Runtime& rt, const cl::Program& p, const cl::Buffer& tmp, const cl::Buffer& dst,
                            const ImageShape& shape, const cl::Event& blurred) {
  cl::Kernel copy(p, "sf_blur_copy");
  const int count = static_cast<int>(shape.plane_texels() * shape.channels);
  detail::KernelArgs(copy).buffer(tmp).buffer(dst).value(count);
  const EventList after{blurred};
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(copy, cl::NullRange, cl::NDRange(ceil_div(count, kBlurCopyChunk)), cl::NDRange(1),
                                  &after, &e);
  return e;
}

// The Gpu family's tile (blur.cl, sf_blur_tiles): a work-group of x * y items (x along a row,
// up to 32 for whole 128-byte lines per warp), `rows` output rows per item.
struct GpuBlurShape {
  int x = 32, y = 8, rows = 4;
  int items() const { return x * y; }
  size_t local_bytes(int radius) const { return size_t(y * rows + 2 * radius) * x * sizeof(float); }
};

// `items` work-items per group, as the table shapes them; rows per item from the table, fewer
// (then narrower groups) until the tile with its 2R halo fits the device's local memory.
GpuBlurShape gpu_blur_shape(const Runtime& rt, int radius, int items) {
  const LaunchDefaults& d = launch_defaults(ScheduleFamily::Gpu);
  GpuBlurShape g;
  g.x = std::min(d.blur_group.x, items);
  g.y = items / g.x;
  g.rows = d.blur_rows_per_item;
  const size_t budget = local_mem_bytes(rt);
  while (g.local_bytes(radius) > budget) {
    if (g.rows > 1) {
      g.rows /= 2;
    } else if (g.y > 1) {
      g.y /= 2;
    } else if (g.x > 1) {
      g.x /= 2;
    } else {
      throw DeviceError("blur: the device's " + std::to_string(budget) +
                        " bytes of local memory do not hold one column of radius " + std::to_string(radius));
    }
  }
  return g;
}

// The Gpu family: src -> out in one launch of sf_blur_tiles, halving the group while the built
// kernel allows fewer items.
cl::Event enqueue_blur_tiles(Runtime& rt, const BlurOptions& blur, bool max_filter, const ScheduleOptions& sched,
                             const cl::Buffer& src, const cl::Buffer& out, const ImageShape& shape,
                             const EventList* wait, Storage storage) {
  int items = gpu_group_items(rt, launch_defaults(ScheduleFamily::Gpu).blur_group.items(), sched.gpu_work_group);
  for (;;) {
    const GpuBlurShape g = gpu_blur_shape(rt, blur.radius, items);
    detail::BuildOptions b;
    add_taps(b.flag("SF_BLUR_GPU"), blur, max_filter)
        .storage(storage)
        .define("SF_BGX", g.x)
        .define("SF_BGY", g.y)
        .define("SF_BROWS", g.rows);
    const cl::Program p = rt.program({"common.clh", "storage.clh", "blur.cl"}, b.str());
    cl::Kernel k(p, "sf_blur_tiles");
    if (kernel_group_limit(rt, k) < size_t(g.items()) && items > 1) {
      items /= 2;
      continue;
    }
    detail::KernelArgs(k)
        .buffer(src)
        .buffer(out)
        .value(shape.width)
        .value(shape.height)
        .value(static_cast<int>(shape.plane_texels()));
    const int tile_rows = g.y * g.rows;
    const cl::NDRange global(size_t(ceil_div(shape.width, g.x)) * g.x, size_t(ceil_div(shape.height, tile_rows)) * g.y,
                             shape.channels);
    cl::Event e;
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global, cl::NDRange(g.x, g.y, 1), wait, &e);
    return e;
  }
}

// enqueue_blur and enqueue_max_filter: the same kernels, summing the Gaussian's taps or taking
// their max.
cl::Event enqueue_separable(Runtime& rt, const BlurOptions& blur, bool max_filter, const ScheduleOptions& sched,
                            Storage storage, const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& tmp,
                            const cl::Buffer& dst, cl::Event* first, const EventList* wait) {
  // rows: the first command, cols: the last.
  struct {
    cl::Event rows, cols;
  } ev;
  const auto done = [&] {
    if (first) *first = ev.rows;
    return ev.cols;
  };
  if (blur.radius == 0) {
    if (src() != dst()) {
      rt.queue().enqueueCopyBuffer(src, dst, 0, 0, shape.bytes(), wait, &ev.rows);
    } else {
      rt.queue().enqueueMarkerWithWaitList(wait, &ev.rows);
    }
    ev.cols = ev.rows;
    return done();
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
  if (resolve_family(rt, sched.family) == ScheduleFamily::Gpu) {
    // One launch cannot blur in place either (a tile's halo rows are another tile's output).
    ev.rows = enqueue_blur_tiles(rt, blur, max_filter, sched, src, in_place ? tmp : dst, shape, wait, storage);
    if (in_place) {
      const EventList after{ev.rows};
      rt.queue().enqueueCopyBuffer(tmp, dst, 0, 0, shape.bytes(), &after, &ev.cols);
    } else {
      ev.cols = ev.rows;
    }
    return done();
  }
  const BlurSchedule s = blur_schedule(rt, blur.radius, sched, shape);
  const cl::Program p =
      rt.program({"common.clh", "storage.clh", "blur.cl"}, blur_build_options(blur, max_filter, s, storage));
  cl::Kernel k(p, "sf_blur");
  detail::KernelArgs(k)
      .buffer(src)
      .buffer(in_place ? tmp : dst)
      .value(shape.width)
      .value(shape.height)
      .value(static_cast<int>(shape.plane_texels()));
  const cl::NDRange global(ceil_div(shape.width, s.strip * s.vec), ceil_div(shape.height, s.rows), shape.channels);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, global, cl::NDRange(1, 1, 1), wait, &ev.rows);
  ev.cols = in_place ? enqueue_copy_back(rt, p, tmp, dst, shape, ev.rows) : ev.rows;
  return done();
}

}  // namespace

cl::Event enqueue_blur(Runtime& rt, const BlurOptions& blur, const ScheduleOptions& sched, Storage storage,
                       const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& tmp, const cl::Buffer& dst,
                       cl::Event* first, const EventList* wait) try {
  return enqueue_separable(rt, blur, false, sched, storage, shape, src, tmp, dst, first, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_blur", e);
}

cl::Event enqueue_max_filter(Runtime& rt, int radius, const ScheduleOptions& sched, const ImageShape& shape,
                             const cl::Buffer& src, const cl::Buffer& dst, cl::Event* first,
                             const EventList* wait) try {
  if (src() == dst()) throw InputError("max filter: dst must not be src");
  check_radius(radius);
  BlurOptions taps;
  taps.radius = radius;
  return enqueue_separable(rt, taps, true, sched, Storage::F32, shape, src, cl::Buffer(), dst, first, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("enqueue_max_filter", e);
}

}  // namespace sf

// Coherent shadow maps on the device: the compression passes (kernels/coherent/compress.cl)
// and the point queries (kernels/coherent/visibility.cl over coherent/query.clh).
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "schedule_defaults.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::coherent {
namespace {

// Texels per work-item of the scan's first pass: the block totals' serial scan stays short
// (65536 blocks for a 4096 x 4096 map) while a block's counts are one contiguous read.
constexpr uint32_t kScanBlock = 256;
// Global sizes are rounded up to whole groups of this many items (the kernels guard the rest).
constexpr size_t kGroupRound = 64;

size_t round_up(size_t n, size_t m) { return (n + m - 1) / m * m; }
size_t scan_blocks(const StackLayout& l) { return (l.texels() + kScanBlock - 1) / kScanBlock; }

// InputError "coherent::<fn>: <field> ..." unless `b` holds at least `bytes` (what: how they
// are counted, for the message).
void need_bytes(const char* fn, const char* field, const cl::Buffer& b, size_t bytes, const std::string& what) {
  if (!b()) throw InputError(std::string("coherent::") + fn + ": " + field + " is empty, needs " + what);
  const size_t have = b.getInfo<CL_MEM_SIZE>();
  if (have < bytes)
    throw InputError(std::string("coherent::") + fn + ": " + field + " holds " + std::to_string(have) +
                     " bytes, needs " + std::to_string(bytes) + " (" + what + ")");
}

void need_stack_input(const char* fn, const StackLayout& l, const cl::Buffer& z1, const cl::Buffer& z2) {
  validate(l);
  const size_t bytes = size_t(l.views()) * l.texels() * sizeof(uint16_t);
  need_bytes(fn, "z1", z1, bytes, "views x texels ushort");
  need_bytes(fn, "z2", z2, bytes, "views x texels ushort");
}

void need_offsets(const char* fn, const StackLayout& l, const cl::Buffer& offsets) {
  need_bytes(fn, "offsets", offsets, (l.texels() + 1) * sizeof(uint32_t), "texels + 1 uint");
}

// The query's arguments: count fits the kernels' uint, points / second / out hold count values.
void need_queries(const char* fn, const cl::Buffer& points, const cl::Buffer& second, const cl::Buffer& out,
                  size_t count) {
  if (count > std::numeric_limits<uint32_t>::max())
    throw InputError(std::string("coherent::") + fn + ": count " + std::to_string(count) +
                     " is more than one launch holds (2^32 - 1)");
  need_bytes(fn, "points", points, count * 16, "count float4");
  need_bytes(fn, "second", second, count * 16, "count float4");
  need_bytes(fn, "out", out, count * sizeof(float), "count float");
}

// Texels per work-item of the count and write passes (coherent/compress.cl SF_COHERENT_LANES): 256 on CPU
// devices (512 contiguous bytes of each map per step of a work-item's walk, which the
// prefetcher follows; 32, 64 and 128 measured slower on PoCL, docs/coherent_device.md), 1
// elsewhere (coalesced across work-items).
uint32_t compress_lanes(const Runtime& rt) {
  return resolve_family(rt, ScheduleFamily::Auto) == ScheduleFamily::Cpu ? 256 : 1;
}

cl::Program compress_program(Runtime& rt) {
  return rt.program({"coherent/compress.cl"},
                    detail::BuildOptions().define("SF_COHERENT_LANES", int(compress_lanes(rt))).str());
}

cl::Program query_program(Runtime& rt) {
  return rt.program({"coherent/query.clh", "coherent/visibility.cl"}, detail::BuildOptions().str());
}

cl::Event launch(Runtime& rt, cl::Kernel& k, size_t items, const EventList* wait) {
  cl::Event e;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(round_up(items, kGroupRound)), cl::NullRange, wait, &e);
  return e;
}

// The point-query kernels of coherent/visibility.cl all take (layout, the stack's buffers,
// positions, points, second, out, count, toward), the stack's buffers being offsets, last and
// depth, or z1 and z2. A count of 0 enqueues a marker.
cl::Event launch_point_queries(Runtime& rt, const char* fn, const char* kernel, const StackLayout& l,
                               std::initializer_list<cl::Buffer> stack, const cl::Buffer& positions,
                               const cl::Buffer& points, const cl::Buffer& second, const cl::Buffer& out, size_t count,
                               CoherentToward toward, const EventList* wait) {
  cl::Event e;
  if (count == 0) {
    rt.queue().enqueueMarkerWithWaitList(wait, &e);
    return e;
  }
  need_queries(fn, points, second, out, count);
  cl::Kernel k(query_program(rt), kernel);
  detail::KernelArgs args(k);
  args.value(device_layout(l));
  for (const cl::Buffer& b : stack) args.buffer(b);
  args.buffer(positions)
      .buffer(points)
      .buffer(second)
      .buffer(out)
      .value(uint32_t(count))
      .value(static_cast<int32_t>(toward));
  return launch(rt, k, count, wait);
}

template <typename T>
cl::Buffer copy_to_device(Runtime& rt, const std::vector<T>& host) {
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, host.size() * sizeof(T),
                    const_cast<T*>(host.data()));
}

}  // namespace

cl::Buffer upload_positions(Runtime& rt, const StackLayout& layout) try {
  return copy_to_device(rt, sequence_positions(layout));
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::upload_positions", e);
}

DeviceStack upload(Runtime& rt, const CompressedStack& stack) try {
  const CompressedStack& c = stack;
  validate(c.layout);
  const size_t texels = c.layout.texels();
  if (c.offsets.size() != texels + 1)
    throw InputError("coherent::upload: offsets holds " + std::to_string(c.offsets.size()) + " words, needs " +
                     std::to_string(texels + 1) + " (texels + 1)");
  if (c.offsets.back() != c.last.size() || c.depth.size() != c.last.size())
    throw InputError("coherent::upload: offsets ends at " + std::to_string(c.offsets.back()) +
                     ", last and depth hold " + std::to_string(c.last.size()) + " and " +
                     std::to_string(c.depth.size()));
  // Every texel holds a segment: the binary search reads [offsets[t], offsets[t + 1] - 1].
  if (c.offsets[0] != 0) throw InputError("coherent::upload: offsets must start at 0");
  for (size_t t = 0; t < texels; ++t)
    if (c.offsets[t + 1] <= c.offsets[t])
      throw InputError("coherent::upload: offsets must increase (every texel holds a segment), texel " +
                       std::to_string(t) + " does not");
  DeviceStack d;
  d.layout = c.layout;
  d.device = device_layout(c.layout);
  d.offsets = copy_to_device(rt, c.offsets);
  d.last = copy_to_device(rt, c.last);
  d.depth = copy_to_device(rt, c.depth);
  d.positions = upload_positions(rt, c.layout);
  d.segment_count = c.last.size();
  return d;
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::upload", e);
}

DeviceDualDepth upload(Runtime& rt, const DualDepthStack& stack) try {
  const DualDepthStack& s = stack;
  validate(s.layout);
  const size_t n = size_t(s.layout.views()) * s.layout.texels();
  if (s.z1.size() != n || s.z2.size() != n)
    throw InputError("coherent::upload: z1 and z2 hold " + std::to_string(s.z1.size()) + " and " +
                     std::to_string(s.z2.size()) + " depths, the layout needs " + std::to_string(n) +
                     " (views x texels)");
  DeviceDualDepth d;
  d.layout = s.layout;
  d.device = device_layout(s.layout);
  d.z1 = copy_to_device(rt, s.z1);
  d.z2 = copy_to_device(rt, s.z2);
  d.positions = upload_positions(rt, s.layout);
  return d;
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::upload", e);
}

CompressedStack download(Runtime& rt, const DeviceStack& stack) try {
  const DeviceStack& d = stack;
  validate(d.layout);
  need_offsets("download", d.layout, d.offsets);
  need_bytes("download", "last", d.last, d.segment_count * sizeof(uint32_t), "segment_count uint");
  need_bytes("download", "depth", d.depth, d.segment_count * sizeof(uint16_t), "segment_count ushort");
  CompressedStack c;
  c.layout = d.layout;
  c.offsets.resize(d.layout.texels() + 1);
  c.last.resize(d.segment_count);
  c.depth.resize(d.segment_count);
  rt.queue().enqueueReadBuffer(d.offsets, CL_TRUE, 0, c.offsets.size() * sizeof(uint32_t), c.offsets.data());
  if (d.segment_count) {
    rt.queue().enqueueReadBuffer(d.last, CL_TRUE, 0, c.last.size() * sizeof(uint32_t), c.last.data());
    rt.queue().enqueueReadBuffer(d.depth, CL_TRUE, 0, c.depth.size() * sizeof(uint16_t), c.depth.data());
  }
  return c;
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::download", e);
}

size_t compress_scratch_bytes(const StackLayout& layout) { return (scan_blocks(layout) + 1) * sizeof(uint64_t); }
size_t compress_total_offset(const StackLayout& layout) { return scan_blocks(layout) * sizeof(uint64_t); }

cl::Event enqueue_compress_count(Runtime& rt, const StackLayout& layout, const cl::Buffer& z1, const cl::Buffer& z2,
                                 const cl::Buffer& offsets, const EventList* wait) try {
  need_stack_input("enqueue_compress_count", layout, z1, z2);
  need_offsets("enqueue_compress_count", layout, offsets);
  cl::Kernel k(compress_program(rt), "sf_coherent_count");
  detail::KernelArgs(k)
      .buffer(z1)
      .buffer(z2)
      .value(uint32_t(layout.texels()))
      .value(uint32_t(layout.views()))
      .buffer(offsets);
  const uint32_t lanes = compress_lanes(rt);
  return launch(rt, k, (layout.texels() + lanes - 1) / lanes, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::enqueue_compress_count", e);
}

cl::Event enqueue_compress_scan(Runtime& rt, const StackLayout& layout, const cl::Buffer& offsets,
                                const cl::Buffer& scratch, cl::Event* first, const EventList* wait) try {
  validate(layout);
  need_offsets("enqueue_compress_scan", layout, offsets);
  need_bytes("enqueue_compress_scan", "scratch", scratch, compress_scratch_bytes(layout),
             "compress_scratch_bytes(layout)");
  const cl::Program p = compress_program(rt);
  const uint32_t texels = uint32_t(layout.texels()), blocks = uint32_t(scan_blocks(layout));
  cl::Kernel a(p, "sf_coherent_scan_blocks"), b(p, "sf_coherent_scan_totals"), c(p, "sf_coherent_scan_add");
  detail::KernelArgs(a).buffer(offsets).value(texels).value(kScanBlock).buffer(scratch).value(blocks);
  detail::KernelArgs(b).buffer(scratch).value(blocks).buffer(offsets).value(texels);
  detail::KernelArgs(c).buffer(offsets).value(texels).value(kScanBlock).buffer(scratch);
  const cl::Event scanned = launch(rt, a, blocks, wait);
  if (first) *first = scanned;
  const EventList after_a{scanned};
  cl::Event totals;
  rt.queue().enqueueNDRangeKernel(b, cl::NullRange, cl::NDRange(1), cl::NullRange, &after_a, &totals);
  const EventList after_b{totals};
  return launch(rt, c, texels, &after_b);
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::enqueue_compress_scan", e);
}

cl::Event enqueue_compress_write(Runtime& rt, const StackLayout& layout, size_t capacity, const cl::Buffer& z1,
                                 const cl::Buffer& z2, const cl::Buffer& offsets, const cl::Buffer& last,
                                 const cl::Buffer& depth, const EventList* wait) try {
  need_stack_input("enqueue_compress_write", layout, z1, z2);
  need_offsets("enqueue_compress_write", layout, offsets);
  if (capacity == 0 || capacity > std::numeric_limits<uint32_t>::max())
    throw InputError("coherent::enqueue_compress_write: capacity must be in [1, 2^32 - 1] segments, got " +
                     std::to_string(capacity));
  need_bytes("enqueue_compress_write", "last", last, capacity * sizeof(uint32_t), "capacity uint");
  need_bytes("enqueue_compress_write", "depth", depth, capacity * sizeof(uint16_t), "capacity ushort");
  cl::Kernel k(compress_program(rt), "sf_coherent_write");
  detail::KernelArgs(k)
      .buffer(z1)
      .buffer(z2)
      .value(uint32_t(layout.texels()))
      .value(uint32_t(layout.views()))
      .buffer(offsets)
      .buffer(last)
      .buffer(depth)
      .value(uint32_t(capacity));
  const uint32_t lanes = compress_lanes(rt);
  return launch(rt, k, (layout.texels() + lanes - 1) / lanes, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::enqueue_compress_write", e);
}

DeviceStack compress_on_device(Runtime& rt, const DeviceDualDepth& stack, const EventList* wait) try {
  const DeviceDualDepth& s = stack;
  const StackLayout& l = s.layout;
  need_stack_input("compress_on_device", l, s.z1, s.z2);
  need_bytes("compress_on_device", "positions", s.positions, size_t(l.views()) * sizeof(uint32_t), "views uint");
  DeviceStack d;
  d.layout = l;
  d.device = device_layout(l);
  d.positions = s.positions;
  d.offsets = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, (l.texels() + 1) * sizeof(uint32_t));
  cl::Buffer scratch(rt.context(), CL_MEM_READ_WRITE, compress_scratch_bytes(l));
  const EventList counted{enqueue_compress_count(rt, l, s.z1, s.z2, d.offsets, wait)};
  const EventList scanned{enqueue_compress_scan(rt, l, d.offsets, scratch, nullptr, &counted)};
  uint64_t total = 0;
  rt.queue().enqueueReadBuffer(scratch, CL_TRUE, compress_total_offset(l), sizeof(total), &total, &scanned);
  if (total > std::numeric_limits<uint32_t>::max())
    throw InputError("coherent::compress_on_device: the stack compresses to " + std::to_string(total) +
                     " segments, more than 32-bit offsets address");
  d.segment_count = size_t(total);  // >= texels >= 1: every texel holds a segment
  d.last = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, d.segment_count * sizeof(uint32_t));
  d.depth = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, d.segment_count * sizeof(uint16_t));
  enqueue_compress_write(rt, l, d.segment_count, s.z1, s.z2, d.offsets, d.last, d.depth, &scanned).wait();
  return d;
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::compress_on_device", e);
}

CompressedStack compress_on_device(Runtime& rt, const DualDepthStack& stack) {
  return download(rt, compress_on_device(rt, upload(rt, stack)));
}

cl::Event enqueue_visibility(Runtime& rt, CoherentFilter filter, CoherentToward toward, size_t count,
                             const DeviceStack& stack, const cl::Buffer& points, const cl::Buffer& second,
                             const cl::Buffer& out, const EventList* wait) try {
  const StackLayout& l = stack.layout;
  validate(l);
  if (filter != CoherentFilter::Nearest && filter != CoherentFilter::Pcf)
    throw InputError("coherent::enqueue_visibility: unknown filter " + std::to_string(static_cast<int>(filter)));
  if (toward != CoherentToward::Direction && toward != CoherentToward::Point)
    throw InputError("coherent::enqueue_visibility: unknown toward " + std::to_string(static_cast<int>(toward)));
  need_offsets("enqueue_visibility", l, stack.offsets);
  if (stack.segment_count < l.texels())
    throw InputError("coherent::enqueue_visibility: segment_count " + std::to_string(stack.segment_count) +
                     " is less than one segment per texel (" + std::to_string(l.texels()) + ")");
  need_bytes("enqueue_visibility", "last", stack.last, stack.segment_count * sizeof(uint32_t), "segment_count uint");
  need_bytes("enqueue_visibility", "depth", stack.depth, stack.segment_count * sizeof(uint16_t),
             "segment_count ushort");
  need_bytes("enqueue_visibility", "positions", stack.positions, size_t(l.views()) * sizeof(uint32_t), "views uint");
  return launch_point_queries(
      rt, "enqueue_visibility",
      filter == CoherentFilter::Pcf ? "sf_coherent_visibility_points_pcf" : "sf_coherent_visibility_points", l,
      {stack.offsets, stack.last, stack.depth}, stack.positions, points, second, out, count, toward, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::enqueue_visibility", e);
}

cl::Event enqueue_stack_test(Runtime& rt, CoherentToward toward, size_t count, const DeviceDualDepth& stack,
                             const cl::Buffer& points, const cl::Buffer& second, const cl::Buffer& out,
                             const EventList* wait) try {
  const StackLayout& l = stack.layout;
  need_stack_input("enqueue_stack_test", l, stack.z1, stack.z2);
  need_bytes("enqueue_stack_test", "positions", stack.positions, size_t(l.views()) * sizeof(uint32_t), "views uint");
  if (toward != CoherentToward::Direction && toward != CoherentToward::Point)
    throw InputError("coherent::enqueue_stack_test: unknown toward " + std::to_string(static_cast<int>(toward)));
  return launch_point_queries(rt, "enqueue_stack_test", "sf_coherent_stack_points", l, {stack.z1, stack.z2},
                              stack.positions, points, second, out, count, toward, wait);
} catch (const cl::Error& e) {
  detail::throw_device_error("coherent::enqueue_stack_test", e);
}

}  // namespace sf::coherent

#pragma once
// Coherent shadow maps on the device (methods.md sec. 5; docs/coherent_device.md): the
// compression of a dual-depth stack (kernels/coherent/compress.cl, byte for byte the scalar
// reference's greedy fit) and the visibility queries of points (kernels/coherent/
// coherent/visibility.cl over coherent/query.clh). Thin wrappers in the toolkit's style and argument order
// (device_types.hpp): buffers are the caller's, every enqueue_* call enqueues after `wait` and returns
// its last event. Bad sizes or empty buffers throw InputError naming the field; OpenCL failures
// DeviceError.
#include <cstddef>

#include "shadowfilter/coherent.hpp"
#include "shadowfilter/device_types.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::coherent {

// A compressed stack in device memory: what the query kernels read.
struct DeviceStack {
  StackLayout layout;
  DeviceLayout device{};     // device_layout(layout): the kernels' sf_coherent_layout
  cl::Buffer offsets;        // uint, texels() + 1
  cl::Buffer last;           // uint, segment_count: the last map of each segment
  cl::Buffer depth;          // ushort, segment_count: z_avg of each segment
  cl::Buffer positions;      // uint, views(): sequence_positions(layout)
  size_t segment_count = 0;  // offsets[texels()]
  // What CompressedStack::compressed_bytes counts (the file's bytes; on the device an index takes 4).
  size_t compressed_bytes() const {
    return (layout.texels() + 1) * 4 + segment_count * size_t(2 + index_bytes(layout));
  }
};

// The uncompressed stack in device memory (ushort z1, z2 of views() x texels() each, map i of the
// sequence at [i * texels + t]) and its positions: the compression's input and the lossless
// tests' ground truth.
struct DeviceDualDepth {
  StackLayout layout;
  DeviceLayout device{};
  cl::Buffer z1, z2;     // ushort, views() texels()
  cl::Buffer positions;  // uint, views()
};

// Copies to and from the device (blocking). upload checks the stack against its layout
// (offsets of texels() + 1 ascending words ending at segments.size(); z1, z2 of views() texels()).
DeviceStack upload(Runtime& rt, const CompressedStack& stack);
DeviceDualDepth upload(Runtime& rt, const DualDepthStack& stack);
CompressedStack download(Runtime& rt, const DeviceStack& stack);
// positions = sequence_positions(layout) in a new device buffer.
cl::Buffer upload_positions(Runtime& rt, const StackLayout& layout);

// --- compression (Ritschel 2007 eq. (1)) ------------------------------------------------------------
// Three passes on caller buffers, each an enqueue:
//   enqueue_compress_count: the segments of every texel into offsets[0 .. texels) (z1, z2 as in
//     DeviceDualDepth; offsets holds texels() + 1 uint);
//   enqueue_compress_scan: the exclusive scan of those counts in place, offsets[texels] = the
//     total; `scratch` (compress_scratch_bytes) ends with the total as a 64-bit word
//     (compress_total_offset), which the host reads before it sizes the segments;
//   enqueue_compress_write: the segments into last (uint) and depth (ushort), `capacity` segments
//     at least the total (segments past it are dropped, so a short buffer loses segments, never
//     memory).
size_t compress_scratch_bytes(const StackLayout& layout);
size_t compress_total_offset(const StackLayout& layout);  // bytes into scratch
cl::Event enqueue_compress_count(Runtime& rt, const StackLayout& layout, const cl::Buffer& z1, const cl::Buffer& z2,
                                 const cl::Buffer& offsets, const EventList* wait = nullptr);
cl::Event enqueue_compress_scan(Runtime& rt, const StackLayout& layout, const cl::Buffer& offsets,
                                const cl::Buffer& scratch, cl::Event* first = nullptr, const EventList* wait = nullptr);
cl::Event enqueue_compress_write(Runtime& rt, const StackLayout& layout, size_t capacity, const cl::Buffer& z1,
                                 const cl::Buffer& z2, const cl::Buffer& offsets, const cl::Buffer& last,
                                 const cl::Buffer& depth, const EventList* wait = nullptr);
// The three passes with the total read in between (blocks until the stack is compressed).
// Throws InputError when the stack holds more segments than 32-bit offsets address.
DeviceStack compress_on_device(Runtime& rt, const DeviceDualDepth& stack, const EventList* wait = nullptr);
// Upload, compress, download: equal to sf::ref::coherent::compress(stack) byte for byte.
CompressedStack compress_on_device(Runtime& rt, const DualDepthStack& stack);

// --- queries ------------------------------------------------------------------------------------
// Nearest: the view whose lat-long cell holds the direction, the texel holding the point, one
// binary test (0 or 1; sf::ref::coherent::visibility). Pcf: generalized PCF, the 2x2 nearest
// views x their 2x2 nearest texels, 16 tests weighted bilinearly (Ritschel 2007 sec. 4.5;
// sf::ref::coherent::visibility_filtered), in [0, 1].
enum class CoherentFilter { Nearest = 0, Pcf = 1 };
// What the second float4 of a query holds (w ignored in both): the direction toward a distant
// light, or the position l of a light sample (semi-local light, direction l - p).
enum class CoherentToward { Direction = 0, Point = 1 };

// Visibility of `count` points (float4, w ignored) toward `second` (float4: directions or light
// positions) -> out (count floats). A point outside the view's map is lit. count 0 enqueues a
// marker.
cl::Event enqueue_visibility(Runtime& rt, CoherentFilter filter, CoherentToward toward, size_t count,
                             const DeviceStack& stack, const cl::Buffer& points, const cl::Buffer& second,
                             const cl::Buffer& out, const EventList* wait = nullptr);
// The uncompressed dual-depth test with the same projection (nearest view and texel): out = +1
// lit (q <= z1, or outside the map), 0 blocked (q >= z2), -1 between the two surfaces, where
// either answer is right (sf::ref::coherent::stack_test).
cl::Event enqueue_stack_test(Runtime& rt, CoherentToward toward, size_t count, const DeviceDualDepth& stack,
                             const cl::Buffer& points, const cl::Buffer& second, const cl::Buffer& out,
                             const EventList* wait = nullptr);

}  // namespace sf::coherent

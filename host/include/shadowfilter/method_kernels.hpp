#pragma once
// A method's own kernels: the basis transform, the reconstruction of visibility from the
// filtered basis, and the raw-depth tests of sm and pcf (methods.md sec. 1-2; kernels/transform.cl,
// reconstruct.cl, pcf.cl). A thin typed wrapper in the argument order of device_types.hpp: buffers are the
// caller's, every call enqueues after `wait` and returns its last command's event.
#include "shadowfilter/device_types.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"
#include "shadowfilter/methods.hpp"

namespace sf {

// depth (W*H floats) -> basis (method.channels planes).
cl::Event enqueue_transform(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width, int height,
                            const cl::Buffer& depth, const cl::Buffer& basis, const EventList* wait = nullptr);

// Visibility of `count` receivers given as (u, v, d) arrays, bilinear lookup of the filtered basis,
// or the footprint lookup of `lookup` (null: bilinear; lookup.hpp: trilinear over a mip chain,
// box via a SAT). receiver_row: receivers per row of the receiver image (DeviceReceivers::row),
// 0 for unstructured points.
struct LookupBuffers;
cl::Event enqueue_reconstruct_points(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width,
                                     int height, size_t count, int receiver_row, const cl::Buffer& basis,
                                     const LookupBuffers* lookup, const cl::Buffer& u, const cl::Buffer& v,
                                     const cl::Buffer& d, const cl::Buffer& visibility,
                                     const EventList* wait = nullptr);
// LookupBuffers::level_offsets for a joined mip layout (chain a sub-buffer of basis, the
// pipeline's); empty when the layout is not joined. Built once, it spares a table per call.
cl::Buffer mip_level_offsets(Runtime& rt, Storage storage, const cl::Buffer& basis, const cl::Buffer& chain,
                             const ImageShape& shape);

// Visibility of one receiver per shadow-map texel (depth image d of the map's size).
cl::Event enqueue_reconstruct_grid(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width,
                                   int height, const cl::Buffer& basis, const cl::Buffer& d,
                                   const cl::Buffer& visibility, const EventList* wait = nullptr);

// sm and pcf (kernels/pcf.cl): H(z - d + bias) per depth texel, weighted by the composite
// Gaussian(opt.blur) (x) bilinear weights of s_ref (methods.md sec. 2), brute force. sm uses the
// bilinear weights only (the prefilter radius does not apply to it). opt.method picks which.
// pcf with opt.lookup mips|sat weights the tests by that lookup's composite weights at the
// receivers' footprints (`footprint`: one f per receiver; empty = 1; `jacobian`: their
// Jacobians, DeviceReceivers::jacobian, read instead of f where opt.lookup.max_anisotropy > 1);
// sm ignores them.
// With opt.receiver_plane, d is each receiver's plane; receiver_row: receivers per row of the
// receiver image (DeviceReceivers::row), 0 for unstructured points.
cl::Event enqueue_pcf_points(Runtime& rt, const FilterOptions& opt, int width, int height, size_t count,
                             int receiver_row, const cl::Buffer& depth, const cl::Buffer& u, const cl::Buffer& v,
                             const cl::Buffer& d, const cl::Buffer& footprint, const cl::Buffer& jacobian,
                             const cl::Buffer& visibility, const EventList* wait = nullptr);
cl::Event enqueue_pcf_grid(Runtime& rt, const FilterOptions& opt, int width, int height, const cl::Buffer& depth,
                           const cl::Buffer& d, const cl::Buffer& visibility, const EventList* wait = nullptr);

}  // namespace sf

#pragma once
// Thin typed wrappers, one per kernel: the public header that fronts the kernels (with
// pyramids.hpp and coherent_device.hpp, which follow the same rules). Buffers are the caller's.
// Images are planar: channel c of a W x H image starts at c * W * H values of the storage format
// (FilterOptions::storage; float32 by default).
//
// One argument order for every enqueue_* function (as CLBlast's clblast.h has one):
//   (Runtime&, method and options, enums, sizes and scalars, input buffers, output buffers
//    [, cl::Event* first], const EventList* wait)
// Every call enqueues on runtime.queue() after the events in `wait` (null: none) and returns the
// event of its last command, so a caller chains its own commands without a host round trip.
// A call that may enqueue several commands (blur, pyramid, SAT, the compression's scan) also
// takes `first`, just before `wait`: when not null it receives the event of the call's first
// command, so event_seconds(*first, returned) is the call's device time on a profiling queue.
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// Normalised Gaussian weights w[0..R] for taps -R..R (w[k] = w[-k]); sigma <= 0 means
// the default (2R+1)/6.
std::vector<float> gaussian_weights(int radius, float sigma);
float default_blur_sigma(int radius);
constexpr int kMaxBlurRadius = 64;

// depth (W*H floats) -> basis (method.channels planes).
cl::Event enqueue_transform(Runtime& rt, const MethodDesc& method, const FilterOptions& opt, int width, int height,
                            const cl::Buffer& depth, const cl::Buffer& basis, const EventList* wait = nullptr);

// Separable Gaussian (rows then columns, clamp-to-edge) of planes in `storage` (shape.value_bytes
// must match), fused in one kernel (kernels/blur.cl): computed in float, rounded once on store.
// Out of place (dst != src) it writes dst directly in one command; in place (dst == src) it
// writes tmp and copies back (first: the blur, returned: the copy-back). Radius 0 copies src to dst.
cl::Event enqueue_blur(Runtime& rt, const BlurOptions& blur, const ScheduleOptions& sched, Storage storage,
                       const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& tmp, const cl::Buffer& dst,
                       cl::Event* first = nullptr, const EventList* wait = nullptr);

// Visibility of `count` receivers given as (u, v, d) arrays, bilinear lookup of the filtered basis,
// or the footprint lookup of `lookup` (null: bilinear; pyramids.hpp: trilinear over a mip chain,
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
// receivers' footprints (`footprint`: one f per receiver; empty = 1); sm ignores them.
// With opt.receiver_plane, d is each receiver's plane; receiver_row: receivers per row of the
// receiver image (DeviceReceivers::row), 0 for unstructured points.
cl::Event enqueue_pcf_points(Runtime& rt, const FilterOptions& opt, int width, int height, size_t count,
                             int receiver_row, const cl::Buffer& depth, const cl::Buffer& u, const cl::Buffer& v,
                             const cl::Buffer& d, const cl::Buffer& footprint, const cl::Buffer& visibility,
                             const EventList* wait = nullptr);
cl::Event enqueue_pcf_grid(Runtime& rt, const FilterOptions& opt, int width, int height, const cl::Buffer& depth,
                           const cl::Buffer& d, const cl::Buffer& visibility, const EventList* wait = nullptr);

}  // namespace sf

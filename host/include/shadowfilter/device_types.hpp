#pragma once
// The small base of device types every public header of the toolkit shares: the wait list,
// an image's shape, the receivers on the device, the stage times, the core of every result and
// the plan of a filter's buffers. It includes only OpenCL and the host image, so the headers of
// the pipeline, its stages, the soft and the layered filters include it and not each other.
//
// The kernel wrappers (method_kernels.hpp, blur.hpp, mips.hpp, sat.hpp, lookup.hpp, classify.hpp,
// coherent_device.hpp) share one argument order (as CLBlast's clblast.h has one):
//   (Runtime&, method and options, enums, sizes and scalars, input buffers, output buffers
//    [, cl::Event* first], const EventList* wait)
// Every call enqueues on runtime.queue() after the events in `wait` (null: none) and returns the
// event of its last command, so a caller chains its own commands without a host round trip.
// A call that may enqueue several commands (blur, pyramid, SAT, the compression's scan) also
// takes `first`, just before `wait`: when not null it receives the event of the call's first
// command, so event_seconds(*first, returned) is the call's device time on a profiling queue.
#include <cstddef>
#include <string>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/opencl.hpp"

namespace sf {

// The events a call waits for: every enqueue_* function and every device method of the toolkit
// takes `const EventList* wait` as its last argument (null = nothing to wait for).
using EventList = std::vector<cl::Event>;

struct ImageShape {
  int width = 0;
  int height = 0;
  int channels = 1;
  int value_bytes = 4;  // bytes per stored value (storage_bytes of the storage format)
  size_t plane_texels() const { return static_cast<size_t>(width) * height; }
  size_t bytes() const { return plane_texels() * channels * value_bytes; }
};

// Receivers on the device: the one receivers type of the hard (Pipeline), soft (SoftFilter) and
// layered (LayeredPipeline) filters, a composed type. Every filter reads `count`, `row` and the
// part for its space: map space (grid, u, v, d, f: a light's shadow-map coordinates; Pipeline and
// SoftFilter) or view space (`view`: camera-view surface points, from which the layered filter
// projects into each layer's map space; LayeredPipeline). A filter refuses receivers whose part
// it reads is empty (InputError) and ignores the other part.
struct DeviceReceivers {
  // Grid mode (one receiver per shadow-map texel; Pipeline only) needs d only.
  bool grid = false;
  size_t count = 0;
  // Map space.
  cl::Buffer u, v, d;
  cl::Buffer f;  // footprints in level-0 texels (points mode); empty = 1 for every receiver
  // Points mode: the receivers' Jacobians, four planes of count floats (dudx, dvdx, dudy, dvdy;
  // footprint.hpp); footprint lookups follow them where FilterOptions::lookup.max_anisotropy > 1.
  // Empty = isotropic at f.
  cl::Buffer jacobian{};
  // Receivers per row of the receiver image, whose neighbours give each receiver's plane
  // (FilterOptions::receiver_plane, SoftOptions::receiver_plane); 0 = unstructured points.
  int row = 0;

  // View space (ViewReceivers, host_image.hpp): `count` floats in each buffer, world positions,
  // view depth (NaN: background, lit) and the world offsets across the pixel along the image's
  // x and y.
  struct View {
    cl::Buffer x, y, z, depth;
    cl::Buffer dxx, dxy, dxz, dyx, dyy, dyz;
  } view{};
};

// Device seconds per stage of the last run, from profiling events (0 on non-profiling queues and
// for stages the run does not have). One type for every filter: the hard pipeline fills the
// basis stages (transform, blur, pyramid, sat) and the ESM classification (zmax, classify), the
// soft filter the stages of its method, the layered pipeline the sum over its layers plus the
// projection and the blend; the host conveniences add the transfers.
struct StageTimes {
  double upload = 0, transform = 0, blur = 0, pyramid = 0, sat = 0, zmax = 0;
  double reconstruct = 0, classify = 0, project = 0, blend = 0, download = 0;
  // Faulting in a new pipeline's buffers on a CPU device (fills of zeros before its first
  // frame, so that no stage pays for their pages), reported with that first frame.
  double resident = 0;
  // Every device stage, the transfers (upload, download) and `resident` not included.
  double total() const { return transform + blur + pyramid + sat + zmax + reconstruct + classify + project + blend; }
  StageTimes& operator+=(const StageTimes& o);  // stage by stage
};

// The core of every host convenience's result (FilterResult, SoftResult, LayeredResult).
struct VisibilityResult {
  HostImage visibility;  // the receivers' size, 1 channel
  StageTimes times;
  size_t background = 0;    // receivers with non-finite depth (output 1)
  size_t outside = 0;       // receivers no map covers (output 1)
  size_t facing_away = 0;   // receivers whose ndl <= 0 (output 0 where the options shadow them)
  size_t device_bytes = 0;  // bytes of the device buffers the run allocated
};

// The device buffers a filter allocates for one set of options and map size.
struct BufferPlan {
  struct Buffer {
    std::string name;  // "basis", "basis+mips", "mip level offsets", "blur scratch", "sat",
                       // "sat bands", "zmax base", "zmax chain"
    size_t bytes = 0;
  };
  ImageShape shape;               // the basis images: width x height x channels of value_bytes
  std::vector<Buffer> buffers;    // allocated by the constructor, in this order
  size_t bytes_per_receiver = 0;  // allocated by reconstruct() per receiver (ESM flags: 1)
  size_t total() const;
  size_t largest() const;
  size_t bytes(const std::string& name) const;  // 0 when the plan has no such buffer
};

}  // namespace sf

#pragma once
// The Gaussian prefilter of basis images (methods.md sec. 2, kernels/blur.cl). A thin typed wrapper in the argument
// order of device_types.hpp: buffers are the caller's, every call enqueues after `wait` and returns its last command's
// event.
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

// Normalised Gaussian weights w[0..R] for taps -R..R (w[k] = w[-k]); sigma <= 0 means
// the default (2R+1)/6.
std::vector<float> gaussian_weights(int radius, float sigma);
float default_blur_sigma(int radius);
constexpr int kMaxBlurRadius = 64;

// Separable Gaussian (rows then columns, clamp-to-edge) of planes in `storage` (shape.value_bytes
// must match), fused in one kernel (kernels/blur.cl): computed in float, rounded once on store.
// Out of place (dst != src) it writes dst directly in one command; in place (dst == src) it
// writes tmp and copies back (first: the blur, returned: the copy-back). Radius 0 copies src to dst.
cl::Event enqueue_blur(Runtime& rt, const BlurOptions& blur, const ScheduleOptions& sched, Storage storage,
                       const ImageShape& shape, const cl::Buffer& src, const cl::Buffer& tmp, const cl::Buffer& dst,
                       cl::Event* first = nullptr, const EventList* wait = nullptr);

// Separable max filter (a dilation) of float32 planes, clamp-to-edge: dst(x, y) is the max of src
// over the (2R+1)^2 window around (x, y) clipped to the image. The blur's kernels and schedule
// (blur.cl built with SF_BLUR_MAX); exact, no rounding. Radius 0 copies. dst must not be src.
// The ESM classification's dilated z-max (classify.hpp).
cl::Event enqueue_max_filter(Runtime& rt, int radius, const ScheduleOptions& sched, const ImageShape& shape,
                             const cl::Buffer& src, const cl::Buffer& dst, cl::Event* first = nullptr,
                             const EventList* wait = nullptr);

}  // namespace sf

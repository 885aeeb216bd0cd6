#include "shadowfilter/pipeline.hpp"

#include <cmath>
#include <sstream>

#include "shadowfilter/errors.hpp"

namespace sf {

void check_fits_device(const Runtime& rt, size_t largest_buffer, size_t total, const std::string& what) {
  const auto& info = rt.info();
  auto mib = [](size_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MiB"; };
  if (largest_buffer > info.max_alloc_bytes || total > info.global_mem_bytes) {
    std::ostringstream s;
    s << what << " needs " << mib(total) << " (largest buffer " << mib(largest_buffer)
      << ") but device '" << info.device_name << "' allows " << mib(info.max_alloc_bytes)
      << " per buffer and " << mib(info.global_mem_bytes) << " in all";
    throw InputError(s.str());
  }
}

Pipeline::Pipeline(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height)
    : rt_(std::move(runtime)), options_(std::move(options)), method_(&find_method(options_.method)) {
  if (width <= 0 || height <= 0)
    throw InputError("shadow map size must be positive, got " + std::to_string(width) + "x" +
                     std::to_string(height));
  method_->validate(options_);
  gaussian_weights(options_.blur.radius, options_.blur.sigma);  // validates the radius
  shape_ = {width, height, method_->channels(options_),
            method_->raw_depth ? 4 : storage_bytes(options_.storage)};
  if (options_.blur.radius > 0 && options_.storage != Storage::F32 && !method_->raw_depth)
    throw InputError(std::string("--storage ") + storage_name(options_.storage) +
                     " with --blur-radius needs the storage-aware blur, not wired yet: use "
                     "--storage f32 to prefilter");
  if (shape_.plane_texels() * shape_.channels > size_t(1) << 31)
    throw InputError("shadow map " + std::to_string(width) + "x" + std::to_string(height) +
                     " is too large (more than 2^31 basis values)");
  check_fits_device(*rt_, shape_.bytes(), 2 * shape_.bytes(), "the basis images");
  basis_ = cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, shape_.bytes());
  if (options_.blur.radius > 0 && !method_->raw_depth) scratch_ = cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, shape_.bytes());
}

cl::Event Pipeline::prefilter(const cl::Buffer& depth, const EventList* wait) {
  transform_done_ = enqueue_transform(*rt_, *method_, options_, depth, shape_.width, shape_.height,
                                      basis_, wait);
  EventList after{transform_done_};
  blur_done_ = BlurEvents{};
  // Raw-depth methods (sm, pcf) weight their tests at the lookup: nothing to prefilter.
  if (options_.blur.radius == 0 || method_->raw_depth) return transform_done_;
  blur_done_ = enqueue_blur(*rt_, options_.blur, options_.schedule, basis_, scratch_, basis_, shape_,
                            &after);
  return blur_done_.cols;
}

cl::Event Pipeline::reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility,
                                const EventList* wait) {
  if (rx.grid) {
    reconstruct_done_ = enqueue_reconstruct_grid(*rt_, *method_, options_, basis_, shape_.width,
                                                 shape_.height, rx.d, visibility, wait);
  } else {
    reconstruct_done_ = enqueue_reconstruct_points(*rt_, *method_, options_, basis_, shape_.width,
                                                   shape_.height, rx.u, rx.v, rx.d, visibility,
                                                   rx.count, wait);
  }
  return reconstruct_done_;
}

StageTimes Pipeline::times() const {
  StageTimes t;
  if (transform_done_()) t.transform = event_seconds(transform_done_);
  if (blur_done_.rows()) t.blur = event_seconds(blur_done_.rows, blur_done_.cols);
  if (reconstruct_done_()) t.reconstruct = event_seconds(reconstruct_done_);
  return t;
}

namespace {

cl::Buffer upload(Runtime& rt, const std::vector<float>& host, EventList& events) {
  cl::Buffer b(rt.context(), CL_MEM_READ_ONLY, host.size() * sizeof(float));
  cl::Event e;
  rt.queue().enqueueWriteBuffer(b, CL_FALSE, 0, host.size() * sizeof(float), host.data(), nullptr, &e);
  events.push_back(e);
  return b;
}

}  // namespace

FilterResult filter(std::shared_ptr<Runtime> runtime, const FilterOptions& options,
                    const HostImage& depth, const Receivers& receivers) {
  Runtime& rt = *runtime;
  if (depth.channels != 1) throw InputError("depth map must have one channel");
  Pipeline pipe(runtime, options, depth.width, depth.height);

  FilterResult result;
  const size_t count = receivers.count();
  const size_t receiver_bytes = count * sizeof(float) * (receivers.grid ? 2 : 4);
  check_fits_device(rt, std::max(pipe.basis_shape().bytes(), count * sizeof(float)),
                    pipe.device_bytes() + depth.data.size() * sizeof(float) + receiver_bytes,
                    "this run");
  for (size_t i = 0; i < count; ++i) {
    if (!std::isfinite(receivers.d[i])) {
      ++result.background;
    } else if (!receivers.grid && !(receivers.u[i] >= 0.0f && receivers.u[i] <= 1.0f &&
                                    receivers.v[i] >= 0.0f && receivers.v[i] <= 1.0f)) {
      ++result.outside;
    }
  }

  EventList uploads;
  cl::Buffer depth_buf = upload(rt, depth.data, uploads);
  DeviceReceivers rx;
  rx.grid = receivers.grid;
  rx.count = count;
  rx.d = upload(rt, receivers.d, uploads);
  if (!receivers.grid) {
    rx.u = upload(rt, receivers.u, uploads);
    rx.v = upload(rt, receivers.v, uploads);
  }
  cl::Buffer vis(rt.context(), CL_MEM_WRITE_ONLY, count * sizeof(float));
  cl::Event filtered = pipe.prefilter(depth_buf, &uploads);
  EventList after{filtered};
  cl::Event rec = pipe.reconstruct(rx, vis, &after);

  result.visibility = HostImage(receivers.width, receivers.height, 1);
  EventList after_rec{rec};
  cl::Event download;
  rt.queue().enqueueReadBuffer(vis, CL_TRUE, 0, count * sizeof(float), result.visibility.data.data(),
                               &after_rec, &download);
  result.times = pipe.times();
  result.times.upload = event_seconds(uploads.front(), uploads.back());
  result.times.download = event_seconds(download);
  result.device_bytes = pipe.device_bytes() + depth.data.size() * sizeof(float) + receiver_bytes +
                        count * sizeof(float);
  return result;
}

}  // namespace sf

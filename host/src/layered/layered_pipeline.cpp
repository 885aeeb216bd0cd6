// LayeredPipeline and filter_layered (layered.hpp): K pipelines around kernels/cascade.cl.
#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <utility>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "resident.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/soft.hpp"

namespace sf {

static_assert(SF_MAX_CASCADES == kMaxCascadeLayers, "SF_MAX_CASCADES and sf::kMaxCascadeLayers must agree");

double layer_reference_texel(const CascadeSet& set, int layer) {
  Point3 centre;
  if (!set.layers.at(layer).transform.unproject(0.5, 0.5, 0.5, centre))
    throw InputError("cascade layer " + std::to_string(layer) + ": its world-to-map matrix is singular");
  return layer_texel_size(set, layer, centre);
}

FilterOptions layer_filter_options(const FilterOptions& options, const CascadeSet& set, int layer) {
  FilterOptions o = options;
  // A warped layer (a projective row 3) stores linear depth on texels whose size changes along the
  // warp, so a planar receiver's depth is not linear across them and the receiver plane from its
  // neighbours misses the support's texels by a fraction of a texel's depth change where the warp
  // compresses: the slope-scaled bias covers that (kWarpedSlopeBias; docs/cascades.md, "What the
  // tests found"), unless the caller asked for more.
  const auto& m = set.layers.at(layer).transform.m;
  if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0)
    o.receiver_plane.slope_bias = std::max(o.receiver_plane.slope_bias, kWarpedSlopeBias);
  if (layer == 0 || options.blur.radius <= 0) return o;
  const double scale = layer_reference_texel(set, 0) / layer_reference_texel(set, layer);
  const double radius = options.blur.radius * scale;
  if (!(radius >= 1.0)) {  // narrower than one of this layer's texels (NaN scale included)
    o.blur.radius = 0;
    o.blur.sigma = 0.0f;
    return o;
  }
  const double sigma0 = options.blur.sigma > 0.0f ? options.blur.sigma : default_blur_sigma(options.blur.radius);
  const long rounded = std::lround(radius);
  if (rounded > kMaxBlurRadius)
    throw InputError("FilterOptions::blur.radius " + std::to_string(options.blur.radius) + " becomes " +
                     std::to_string(rounded) + " texels in cascade layer " + std::to_string(layer) +
                     " (its texels are " + std::to_string(scale) + " times finer than layer 0's), past the limit " +
                     std::to_string(kMaxBlurRadius));
  o.blur.radius = static_cast<int>(rounded);
  o.blur.sigma = static_cast<float>(sigma0 * scale);
  return o;
}

SoftLight layer_soft_light(const CascadeSet& set, int layer, double size, double height, double light_plane) {
  const std::string name = "cascade layer " + std::to_string(layer);
  const auto& m = set.layers.at(layer).transform.m;
  if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0)
    throw InputError(name + " is warped (a projective row 3): the soft methods need orthographic layers");
  const auto row = [&](int r) { return Point3{m[4 * r], m[4 * r + 1], m[4 * r + 2]}; };
  const Point3 gu = row(0), gv = row(1), gd = row(2);
  const double su = length(gu), sv = length(gv), sd = length(gd);
  if (!(su > 0.0 && sv > 0.0 && sd > 0.0) || !std::isfinite(su * sv * sd))
    throw InputError(name + ": its u, v and d rows must be finite and non-zero");
  // A map whose u or v leans along the light's axis has no rectangle of constant size for the
  // light's footprint (1e-6: rounding of matrices written to text).
  if (std::abs(dot(gu, gd)) > 1e-6 * su * sd || std::abs(dot(gv, gd)) > 1e-6 * sv * sd)
    throw InputError(name + ": its u and v rows must be perpendicular to its d row (the light's axis)");
  if (!std::isfinite(light_plane)) throw InputError("the light's plane must be a finite depth");
  SoftLight L;
  L.perspective = false;
  L.size = size;
  L.height = height < 0.0 ? size * sv / su : height * sv / su;
  L.extent = 1.0 / su;
  L.near_plane = -m[11] / sd;
  L.far_plane = L.near_plane + 1.0 / sd;
  L.light_distance = L.near_plane - light_plane;
  return L;
}

DeviceReceivers upload_view_receivers(Runtime& runtime, const ViewReceivers& view, EventList* events) {
  const size_t count = view.count();
  const std::vector<float>* host[] = {&view.x,   &view.y,   &view.z,   &view.depth, &view.dxx,
                                      &view.dxy, &view.dxz, &view.dyx, &view.dyy,   &view.dyz};
  for (const auto* a : host)
    if (a->size() != count) throw InputError("the view receivers' data does not match their size");
  DeviceReceivers rx;
  rx.count = count;
  rx.row = view.width;
  DeviceReceivers::View& w = rx.view;
  cl::Buffer* device[] = {&w.x, &w.y, &w.z, &w.depth, &w.dxx, &w.dxy, &w.dxz, &w.dyx, &w.dyy, &w.dyz};
  try {
    for (int n = 0; n < 10; ++n) {
      *device[n] = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY, std::max<size_t>(count, 1) * sizeof(float));
      if (count == 0) continue;
      cl::Event written;
      runtime.queue().enqueueWriteBuffer(*device[n], events ? CL_FALSE : CL_TRUE, 0, count * sizeof(float),
                                         host[n]->data(), nullptr, events ? &written : nullptr);
      if (events) events->push_back(written);
    }
  } catch (const cl::Error& e) {
    detail::throw_device_error("upload_view_receivers", e);
  }
  return rx;
}

namespace {

// The set as the kernels read it: doubles rounded once to float; the receivers' normal offset in
// each layer's texels (normal_offset.hpp).
sf_cascade_params cascade_params(const CascadeSet& set, float normal_offset) {
  sf_cascade_params p{};
  p.normal_offset = normal_offset;
  p.count = static_cast<sf_int>(set.layers.size());
  p.width = set.width;
  p.height = set.height;
  p.blend = static_cast<float>(set.blend);
  for (size_t k = 0; k < set.layers.size(); ++k) {
    for (int e = 0; e < 16; ++e) p.m[16 * k + e] = static_cast<float>(set.layers[k].transform.m[e]);
    p.split_near[k] = static_cast<float>(set.layers[k].split_near);
    p.split_far[k] = static_cast<float>(set.layers[k].split_far);
  }
  return p;
}

// The cascade kernels of a set of `layers` (SF_CASCADES: the projection's loops have fixed trip
// counts, kernels/cascade.cl).
cl::Kernel cascade_kernel(Runtime& rt, const char* name, int layers) {
  return cl::Kernel(rt.program({"cascade.cl"}, detail::BuildOptions().define("SF_CASCADES", layers).str()), name);
}

}  // namespace

LayeredPipeline::LayeredPipeline(std::shared_ptr<Runtime> runtime, const FilterOptions& options, CascadeSet set) try
    : rt_(std::move(runtime)), set_(std::move(set)) {
  validate(set_);
  sf_cascade_params params = cascade_params(set_, normal_offset(options));
  params_ = cl::Buffer(rt_->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof params, &params);
  for (int k = 0; k < static_cast<int>(set_.layers.size()); ++k)
    pipes_.push_back(std::make_unique<Pipeline>(rt_, layer_filter_options(options, set_, k), set_.width, set_.height));
  size_t total = 0, largest = 0;
  for (const auto& p : pipes_) total += p->device_bytes(), largest = std::max(largest, p->buffer_plan().largest());
  check_fits_device(*rt_, largest, total, "the layered pipeline's buffers");
} catch (const cl::Error& e) {
  detail::throw_device_error("LayeredPipeline::LayeredPipeline", e);
}

LayeredPipeline::LayeredPipeline(std::shared_ptr<Runtime> runtime, const SoftOptions& options, CascadeSet set,
                                 double light_plane) try
    : rt_(std::move(runtime)), set_(std::move(set)) {
  validate(set_);
  sf_cascade_params params = cascade_params(set_, soft_normal_offset(options));
  params_ = cl::Buffer(rt_->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof params, &params);
  for (int k = 0; k < static_cast<int>(set_.layers.size()); ++k) {
    SoftOptions o = options;
    o.light = layer_soft_light(set_, k, options.light.size, options.light.height, light_plane);
    o.light.weight = options.light.weight;
    soft_.push_back(std::make_unique<SoftFilter>(rt_, o, set_.width, set_.height));
  }
  size_t total = 0;
  for (const auto& f : soft_) total += f->device_bytes();
  check_fits_device(*rt_, soft_.front()->device_bytes(), total, "the layered soft filters' buffers");
} catch (const cl::Error& e) {
  detail::throw_device_error("LayeredPipeline::LayeredPipeline", e);
}

Pipeline& LayeredPipeline::layer(int k) {
  if (soft() || k < 0 || k >= layer_count())
    throw InputError("LayeredPipeline::layer(" + std::to_string(k) + "): no such layer of FilterOptions");
  return *pipes_[k];
}

const Pipeline& LayeredPipeline::layer(int k) const { return const_cast<LayeredPipeline*>(this)->layer(k); }

SoftFilter& LayeredPipeline::soft_layer(int k) {
  if (!soft() || k < 0 || k >= layer_count())
    throw InputError("LayeredPipeline::soft_layer(" + std::to_string(k) + "): no such layer of SoftOptions");
  return *soft_[k];
}

size_t LayeredPipeline::bytes_per_receiver(int layers) {
  return size_t(layers) * 5 * sizeof(float) + sizeof(cl_char2) + sizeof(float);
}

size_t LayeredPipeline::device_bytes() const {
  size_t total = 0;
  for (const auto& p : pipes_) total += p->device_bytes();
  for (const auto& f : soft_) total += f->device_bytes();
  if (proj_.count)
    total += size_t(layer_count()) * proj_.stride * (proj_.jacobian() ? 9 : 5) * sizeof(float) + proj_.count * 6;
  return total;
}

// Each per-layer array is one buffer of K planes; plane k starts at k * stride, a multiple of
// the device's sub-buffer alignment, so every layer's pipeline gets plain sub-buffers.
void LayeredPipeline::allocate(size_t count) {
  const int K = layer_count();
  const size_t align = std::max<size_t>(rt_->device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8, 4) / 4;
  const size_t stride = (count + align - 1) / align * align;
  const size_t plane_bytes = stride * sizeof(float), all_bytes = K * plane_bytes;
  // The Jacobians, where some layer's lookup follows them (footprint.hpp).
  bool jacobian = soft();  // the soft methods' footprint rectangles
  for (const auto& p : pipes_) jacobian = jacobian || p->options().lookup.follows_jacobian();
  check_fits_device(
      *rt_, std::max((jacobian ? 4 : 1) * all_bytes, soft() ? size_t(0) : pipes_.front()->buffer_plan().largest()),
      device_bytes() + (jacobian ? 9 : 5) * all_bytes + count * 6, "the layered receivers");
  proj_ = Projection{};
  layer_rx_.clear();
  layer_vis_.clear();
  const cl::Context& ctx = rt_->context();
  proj_.count = count;
  proj_.stride = stride;
  proj_.layers = cl::Buffer(ctx, CL_MEM_READ_WRITE, count * sizeof(cl_char2));
  proj_.weight = cl::Buffer(ctx, CL_MEM_READ_WRITE, count * sizeof(float));
  for (cl::Buffer* b : {&proj_.u, &proj_.v, &proj_.d, &proj_.f, &proj_.visibility})
    *b = cl::Buffer(ctx, CL_MEM_READ_WRITE, all_bytes);
  if (jacobian) proj_.jacobian = cl::Buffer(ctx, CL_MEM_READ_WRITE, 4 * all_bytes);
  for (int k = 0; k < K; ++k) {
    const size_t origin = k * plane_bytes, bytes = count * sizeof(float);
    DeviceReceivers rx;
    rx.count = count;
    rx.u = sub_buffer(*rt_, proj_.u, origin, bytes);
    rx.v = sub_buffer(*rt_, proj_.v, origin, bytes);
    rx.d = sub_buffer(*rt_, proj_.d, origin, bytes);
    rx.f = sub_buffer(*rt_, proj_.f, origin, bytes);
    if (jacobian) rx.jacobian = sub_buffer(*rt_, proj_.jacobian, 4 * origin, 4 * bytes);
    layer_rx_.push_back(rx);
    layer_vis_.push_back(sub_buffer(*rt_, proj_.visibility, origin, bytes));
  }
  // Every buffer's pages in before the frame runs in them (resident.hpp).
  resident_done_ = detail::fault_in(
      *rt_, {&proj_.layers, &proj_.weight, &proj_.u, &proj_.v, &proj_.d, &proj_.f, &proj_.visibility, &proj_.jacobian},
      &resident_first_);
}

cl::Event LayeredPipeline::prefilter(const std::vector<cl::Buffer>& depth, const EventList* wait) try {
  if (depth.size() != size_t(layer_count()))
    throw InputError("LayeredPipeline::prefilter: " + std::to_string(depth.size()) + " depth buffers for " +
                     std::to_string(layer_count()) + " layers");
  resident_first_ = resident_done_ = cl::Event();  // a frame reports the buffers it allocated
  EventList done;
  for (size_t k = 0; k < pipes_.size(); ++k) done.push_back(pipes_[k]->prefilter(depth[k], wait));
  for (size_t k = 0; k < soft_.size(); ++k) done.push_back(soft_[k]->prefilter(depth[k], wait));
  cl::Event all;
  rt_->queue().enqueueMarkerWithWaitList(&done, &all);
  return all;
} catch (const cl::Error& e) {
  detail::throw_device_error("LayeredPipeline::prefilter", e);
}

void LayeredPipeline::set_depth_ranges(const std::vector<MapRange>& ranges) {
  if (ranges.size() != size_t(layer_count()))
    throw InputError("LayeredPipeline::set_depth_ranges: " + std::to_string(ranges.size()) + " ranges for " +
                     std::to_string(layer_count()) + " layers");
  for (size_t k = 0; k < pipes_.size(); ++k) pipes_[k]->set_depth_range(ranges[k]);
}

cl::Event LayeredPipeline::reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility,
                                       const EventList* wait) try {
  const DeviceReceivers::View& w = rx.view;
  const cl::Buffer* inputs[] = {&w.x, &w.y, &w.z, &w.depth, &w.dxx, &w.dxy, &w.dxz, &w.dyx, &w.dyy, &w.dyz};
  const char* names[] = {"x", "y", "z", "depth", "dxx", "dxy", "dxz", "dyx", "dyy", "dyz"};
  for (int n = 0; n < 10; ++n)
    if (rx.count > 0 && !(*inputs[n])())
      throw InputError(std::string("DeviceReceivers::view.") + names[n] + " is an empty buffer");
  if (!visibility()) throw InputError("LayeredPipeline::reconstruct: the visibility buffer is empty");
  if (rx.count > size_t(INT_MAX)) throw InputError("DeviceReceivers::count exceeds 2^31 - 1");
  if (rx.row < 0) throw InputError("DeviceReceivers::row must not be negative");
  if (rx.count == 0) {
    cl::Event none;
    rt_->queue().enqueueMarkerWithWaitList(wait, &none);
    return none;
  }
  if (rx.count != proj_.count) allocate(rx.count);
  const int count = static_cast<int>(rx.count), stride = static_cast<int>(proj_.stride);

  cl::Kernel project = cascade_kernel(*rt_, "sf_cascade_project", layer_count());
  detail::KernelArgs args(project);
  for (const cl::Buffer* b : inputs) args.buffer(*b);
  args.value(count).buffer(params_).value(stride).buffer(proj_.layers).buffer(proj_.weight);
  args.buffer(proj_.u).buffer(proj_.v).buffer(proj_.d).buffer(proj_.f).optional(proj_.jacobian);
  // kCascadeVector receivers per work-item (SF_CASCADE_VEC in cascade.cl).
  constexpr size_t kCascadeVector = 16;
  const cl::NDRange items((rx.count + kCascadeVector - 1) / kCascadeVector);
  rt_->queue().enqueueNDRangeKernel(project, cl::NullRange, items, cl::NullRange, wait, &project_done_);

  // Every layer over all receivers; footprints only where the lookup reads them (as filter()).
  EventList projected{project_done_}, layers_done;
  for (size_t k = 0; k < pipes_.size(); ++k) {
    DeviceReceivers layer_rx = layer_rx_[k];
    layer_rx.row = rx.row;
    if (pipes_[k]->options().lookup.kind == Lookup::Bilinear) layer_rx.f = layer_rx.jacobian = cl::Buffer();
    layers_done.push_back(pipes_[k]->reconstruct(layer_rx, layer_vis_[k], &projected));
  }
  for (size_t k = 0; k < soft_.size(); ++k) {  // the soft methods read every footprint
    DeviceReceivers layer_rx = layer_rx_[k];
    layer_rx.row = rx.row;
    layers_done.push_back(soft_[k]->reconstruct(layer_rx, layer_vis_[k], &projected));
  }

  cl::Kernel blend = cascade_kernel(*rt_, "sf_cascade_blend", layer_count());
  detail::KernelArgs(blend)
      .buffer(proj_.layers)
      .buffer(proj_.weight)
      .buffer(proj_.visibility)
      .value(stride)
      .value(count)
      .buffer(visibility);
  rt_->queue().enqueueNDRangeKernel(blend, cl::NullRange, cl::NDRange(rx.count), cl::NullRange, &layers_done,
                                    &blend_done_);
  return blend_done_;
} catch (const cl::Error& e) {
  detail::throw_device_error("LayeredPipeline::reconstruct", e);
}

StageTimes LayeredPipeline::times() const try {
  StageTimes t;
  for (const auto& p : pipes_) t += p->times();
  for (const auto& f : soft_) t += f->times();
  if (project_done_()) t.project = event_seconds(project_done_);
  if (blend_done_()) t.blend = event_seconds(blend_done_);
  t.resident += detail::resident_seconds(resident_first_, resident_done_);
  return t;
} catch (const cl::Error& e) {
  detail::throw_device_error("LayeredPipeline::times", e);
}

namespace {

// The maps and receivers filter_layered takes: one map per layer of the set's size, ndl as long
// as the view.
void check_layered_inputs(const CascadeSet& set, const std::vector<HostImage>& maps, const ViewReceivers& view) {
  validate(set);
  if (maps.size() != set.layers.size())
    throw InputError("filter_layered: " + std::to_string(maps.size()) + " depth maps for " +
                     std::to_string(set.layers.size()) + " cascade layers");
  for (size_t k = 0; k < maps.size(); ++k) {
    const HostImage& m = maps[k];
    if (m.channels != 1 || m.width != set.width || m.height != set.height || m.data.size() != m.texels())
      throw InputError("filter_layered: depth map " + std::to_string(k) + " is not one channel of " +
                       std::to_string(set.width) + "x" + std::to_string(set.height));
  }
  if (!view.ndl.empty() && view.ndl.size() != view.count())
    throw InputError("filter_layered: the view receivers' ndl does not match their size");
}

// Uploads, runs `pipe` (ready: its depth ranges set), downloads and counts.
LayeredResult run_layered(Runtime& rt, LayeredPipeline& pipe, bool facing_away_shadowed,
                          const std::vector<HostImage>& maps, const ViewReceivers& view) {
  const CascadeSet& set = pipe.cascades();
  const size_t count = view.count();
  LayeredResult result;
  result.visibility = HostImage(view.width, view.height, 1);
  const size_t input_bytes = (maps.size() * set.width * size_t(set.height) + 10 * count + count) * sizeof(float);
  check_fits_device(rt, std::max(size_t(set.width) * set.height, count) * sizeof(float),
                    pipe.device_bytes() + input_bytes + count * LayeredPipeline::bytes_per_receiver(pipe.layer_count()),
                    "this run");
  EventList uploads;
  auto upload = [&](const std::vector<float>& host) {
    cl::Buffer b(rt.context(), CL_MEM_READ_ONLY, std::max<size_t>(host.size(), 1) * sizeof(float));
    if (!host.empty()) {
      cl::Event e;
      rt.queue().enqueueWriteBuffer(b, CL_FALSE, 0, host.size() * sizeof(float), host.data(), nullptr, &e);
      uploads.push_back(e);
    }
    return b;
  };
  std::vector<cl::Buffer> depth;
  for (const HostImage& m : maps) depth.push_back(upload(m.data));
  const DeviceReceivers rx = upload_view_receivers(rt, view, &uploads);
  cl::Buffer vis(rt.context(), CL_MEM_WRITE_ONLY, std::max<size_t>(count, 1) * sizeof(float));

  EventList filtered{pipe.prefilter(depth, uploads.empty() ? nullptr : &uploads)};
  EventList done{pipe.reconstruct(rx, vis, &filtered)};
  std::vector<cl_char2> choice(count);
  cl::Event download;
  if (count) {
    rt.queue().enqueueReadBuffer(vis, CL_TRUE, 0, count * sizeof(float), result.visibility.data.data(), &done,
                                 &download);
    rt.queue().enqueueReadBuffer(pipe.projection().layers, CL_TRUE, 0, count * sizeof(cl_char2), choice.data(), &done);
  }

  result.per_layer.assign(set.layers.size(), 0);
  for (size_t i = 0; i < count; ++i) {
    const cl_char2 l = choice[i];
    if (!std::isfinite(view.depth[i])) {
      ++result.background;
    } else if (l.s[0] < 0) {
      ++result.outside;
    } else {
      ++result.per_layer[l.s[0]];
      if (l.s[1] >= 0) ++result.per_layer[l.s[1]], ++result.blended;
    }
    if (facing_away_shadowed && !view.ndl.empty() && view.ndl[i] <= 0.0f && std::isfinite(view.depth[i])) {
      result.visibility.data[i] = 0.0f;
      ++result.facing_away;
    }
  }
  result.times = pipe.times();
  if (!uploads.empty()) result.times.upload = event_seconds(uploads.front(), uploads.back());
  if (download()) result.times.download = event_seconds(download);
  result.device_bytes = pipe.device_bytes() + input_bytes;
  return result;
}

}  // namespace

LayeredResult filter_layered(std::shared_ptr<Runtime> runtime, const FilterOptions& options, const CascadeSet& set,
                             const std::vector<HostImage>& maps, const ViewReceivers& view) try {
  check_layered_inputs(set, maps, view);
  LayeredPipeline pipe(runtime, options, set);
  // The maps' ranges from their host copies where the lookup's limit depends on them: a map the
  // lookup cannot hold is refused before anything is enqueued.
  if (options.depth_range || (options.lookup.kind == Lookup::Sat && pipe.layer(0).method().sat_limit)) {
    std::vector<MapRange> ranges;
    for (const HostImage& m : maps) ranges.push_back(options.depth_range ? *options.depth_range : depth_range(m));
    pipe.set_depth_ranges(ranges);
  }
  return run_layered(*runtime, pipe, options.facing_away_shadowed, maps, view);
} catch (const cl::Error& e) {
  detail::throw_device_error("filter_layered", e);
}

LayeredResult filter_layered(std::shared_ptr<Runtime> runtime, const SoftOptions& options, const CascadeSet& set,
                             double light_plane, const std::vector<HostImage>& maps, const ViewReceivers& view) try {
  check_layered_inputs(set, maps, view);
  LayeredPipeline pipe(runtime, options, set, light_plane);
  return run_layered(*runtime, pipe, options.facing_away_shadowed, maps, view);
} catch (const cl::Error& e) {
  detail::throw_device_error("filter_layered", e);
}

}  // namespace sf

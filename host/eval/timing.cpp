// Timing a configuration honestly: the inputs on the device, warm-up, the median of repeated
// runs, device stage times from profiling events; and one evaluated row.
#include <algorithm>
#include <chrono>

#include "eval_util.hpp"
#include "evaluate.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {

using detail::median;

namespace {

// A read-only device copy of `h` (at least 4 bytes: OpenCL refuses empty buffers).
cl::Buffer upload(Runtime& rt, const std::vector<float>& h) {
  cl::Buffer b(rt.context(), CL_MEM_READ_ONLY, std::max<size_t>(4, h.size() * sizeof(float)));
  if (!h.empty()) rt.queue().enqueueWriteBuffer(b, CL_TRUE, 0, h.size() * sizeof(float), h.data());
  return b;
}

// The row's errors against the ray-traced references (only the receivers facing the light count,
// Scene::traced) and its acne and leaks.
void traced_errors(Row& row, const Scene& scene, const std::vector<float>& v) {
  auto vs_image = [&](const HostImage& img) {
    if (img.texels() != v.size()) return ErrorStats{};
    return error_stats(v, std::vector<double>(img.data.begin(), img.data.end()), scene.traced);
  };
  row.hard = vs_image(scene.ref_hard);
  row.soft = vs_image(scene.ref_soft);
  row.acne_leak = acne_leak(v, scene.ref_hard, scene.traced);
}

// Warm-up, then runs of prefilter + reconstruct + finish of a filter in Pipeline's shape (Pipeline,
// SoftFilter): median and min wall ms, the median of each stage's device time, the visibility.
template <class Filter>
Measured time_filter(Runtime& rt, Filter& filter, const cl::Buffer& depth, const DeviceReceivers& rx,
                     const TimingSettings& t) {
  using Clock = std::chrono::steady_clock;
  auto& q = rt.queue();
  cl::Buffer vis(rt.context(), CL_MEM_WRITE_ONLY, std::max<size_t>(4, rx.count * sizeof(float)));
  Measured m;
  std::vector<double> wall, tr, bl, rc, py, sa, zm, cls;
  for (int i = 0; i < t.warmup + std::max(1, t.runs); ++i) {
    const auto t0 = Clock::now();
    cl::Event f = filter.prefilter(depth);
    EventList after{f};
    filter.reconstruct(rx, vis, &after);
    q.finish();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (i < t.warmup) continue;
    wall.push_back(ms);
    const StageTimes s = filter.times();
    tr.push_back(s.transform), bl.push_back(s.blur), rc.push_back(s.reconstruct), py.push_back(s.pyramid);
    sa.push_back(s.sat), zm.push_back(s.zmax), cls.push_back(s.classify);
  }
  m.runs = int(wall.size());
  m.median_ms = median(wall);
  m.min_ms = *std::min_element(wall.begin(), wall.end());
  m.stages.transform = median(tr);
  m.stages.blur = median(bl);
  m.stages.reconstruct = median(rc);
  m.stages.pyramid = median(py);
  m.stages.sat = median(sa);
  m.stages.zmax = median(zm);
  m.stages.classify = median(cls);
  m.visibility.resize(rx.count);
  if (rx.count) q.enqueueReadBuffer(vis, CL_TRUE, 0, rx.count * sizeof(float), m.visibility.data());
  return m;
}

}  // namespace

// --- timing ----------------------------------------------------------------------------------------

Measured measure(const std::shared_ptr<Runtime>& rt, const FilterOptions& o, const Scene& scene,
                 const TimingSettings& t) {
  const Receivers& r = scene.receivers;
  // The map's depth range from the host copy: refused lookups throw here, and prefilter() runs
  // no range reduction inside the timed loop.
  FilterOptions run = o;
  if (!run.depth_range) run.depth_range = depth_range(scene.depth);
  Pipeline pipe(rt, run, scene.depth.width, scene.depth.height);  // validates, may throw InputError
  auto up = [&](const std::vector<float>& h) { return upload(*rt, h); };
  const size_t count = r.count();
  cl::Buffer depth = up(scene.depth.data);
  DeviceReceivers rx;
  rx.grid = r.grid;
  rx.count = count;
  rx.row = r.grid ? 0 : r.width;  // the receiver image's neighbours give the receiver planes
  rx.d = up(r.d);
  size_t rx_bytes = count * sizeof(float);
  if (!r.grid) {
    rx.u = up(r.u);
    rx.v = up(r.v);
    rx_bytes += 2 * count * sizeof(float);
    if (r.has_footprint && o.lookup.kind != Lookup::Bilinear) {
      rx.f = up(r.f);
      rx_bytes += count * sizeof(float);
    }
  }
  Measured m = time_filter(*rt, pipe, depth, rx, t);
  m.device_bytes = pipe.device_bytes() + scene.depth.data.size() * sizeof(float) + rx_bytes + count * sizeof(float);
  return m;
}

// A result row's identity and timings; the caller adds the errors it needs.
Row timed_row(const Scene& scene, const std::string& method, const std::string& label, const Measured& m) {
  Row row;
  row.scene = scene.name;
  row.method = method;
  row.label = label;
  row.time_ms = m.median_ms;
  row.min_ms = m.min_ms;
  row.stages = m.stages;
  row.device_bytes = m.device_bytes;
  row.runs = m.runs;
  return row;
}

Row timed_row(const Scene& scene, const FilterOptions& o, const Measured& m) {
  Row row = timed_row(scene, o.method.name(), config_label(o), m);
  row.options = o;
  return row;
}

Row evaluate_config(const std::shared_ptr<Runtime>& rt, const Scene& scene, const FilterOptions& o, SrefCache& sref,
                    const TimingSettings& t, const std::vector<double>* target_ref) {
  Measured m = measure(rt, o, scene, t);
  Row row = timed_row(scene, o, m);
  row.sref = error_stats(m.visibility, sref.for_options(o), scene.valid);
  // The target, like self, is s_ref: defined on every valid receiver, facing the light or not.
  if (target_ref) row.target = error_stats(m.visibility, *target_ref, scene.valid);
  traced_errors(row, scene, m.visibility);
  row.visibility = std::move(m.visibility);
  return row;
}

Measured measure(const std::shared_ptr<Runtime>& rt, const SoftOptions& opt, const Scene& scene,
                 const TimingSettings& t) {
  if (!scene.light)
    throw InputError((scene.no_light.empty() ? std::string("the scene has no area light") : scene.no_light) +
                     ": the soft methods need one");
  SoftOptions o = opt;
  o.light = *scene.light;
  SoftFilter filter(rt, o, scene.depth.width, scene.depth.height);  // validates, may throw InputError
  auto up = [&](const std::vector<float>& h) { return upload(*rt, h); };
  const Receivers& r = scene.receivers;
  const size_t count = r.count();
  cl::Buffer depth = up(scene.depth.data);
  DeviceReceivers rx;
  rx.count = count;
  rx.row = r.width;
  if (r.grid) {  // SoftFilter takes points: a planar receiver sits at its texel's centre
    std::vector<float> u(count), v(count);
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x) {
        u[size_t(y) * r.width + x] = (x + 0.5f) / float(scene.depth.width);
        v[size_t(y) * r.width + x] = (y + 0.5f) / float(scene.depth.height);
      }
    rx.u = up(u);
    rx.v = up(v);
  } else {
    rx.u = up(r.u);
    rx.v = up(r.v);
    if (r.has_footprint) rx.f = up(r.f);
  }
  rx.d = up(r.d);
  Measured m = time_filter(*rt, filter, depth, rx, t);
  m.device_bytes = filter.device_bytes() + scene.depth.data.size() * sizeof(float) +
                   (r.has_footprint && !r.grid ? 5 : 4) * count * sizeof(float);
  return m;
}

Row evaluate_soft_config(const std::shared_ptr<Runtime>& rt, const Scene& scene, const SoftOptions& opt,
                         const TimingSettings& t) {
  Measured m = measure(rt, opt, scene, t);
  SoftOptions o = opt;
  o.light = *scene.light;
  Row row = timed_row(scene, soft_method_name(o.method), soft_label(o), m);
  row.soft_options = o;
  traced_errors(row, scene, m.visibility);
  row.visibility = std::move(m.visibility);
  return row;
}

}  // namespace sf::eval

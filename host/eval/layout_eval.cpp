// evaluate-layouts: layouts x cascade counts x methods at equal total texels along a camera path
// (layout_eval.hpp).
#include "layout_eval.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "drawing.hpp"
#include "eval_util.hpp"
#include "output_file.hpp"
#include "layer_render.hpp"
#include "scene_library.hpp"
#include "scene_render.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/layered.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::eval {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::vector<LayoutConfig> make_configs(const LayoutEvalRequest& r) {
  std::vector<LayoutConfig> configs;
  for (const std::string& name : r.layouts) {
    const LayoutKind kind = parse_layout(name);
    if (kind == LayoutKind::Single || kind == LayoutKind::Tsm) {
      configs.push_back({kind, 1, true, r.total_size});
      continue;
    }
    for (int k : r.cascade_counts) {
      configs.push_back({kind, k, true, equal_texel_side(r.total_size, k)});
      if (kind == LayoutKind::Pssm && r.unstabilized_too)
        configs.push_back({kind, k, false, equal_texel_side(r.total_size, k)});
    }
  }
  return configs;
}

struct Accumulator {
  LayoutRow row;
  FrameMetrics sum;
  size_t frames_soft = 0;
  double flicker_sum = 0;
  int flicker_pairs = 0;
  std::vector<double> times, prefilter, reconstruct;
};

// Mean |(v - ref) - (v_last - ref_last)| over mask: the change of the error at each point
// (0 when the mask is empty).
double mean_error_change(const std::vector<float>& v, const std::vector<float>& ref, const std::vector<float>& v_last,
                         const std::vector<float>& ref_last, const std::vector<uint8_t>& mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < v.size(); ++i)
    if (mask[i]) sum += std::abs((double(v[i]) - ref[i]) - (double(v_last[i]) - ref_last[i])), ++n;
  return n ? sum / n : 0.0;
}

// The light's direction turned `degrees` about the world's up axis (y).
scene::Vec3 turned_about_up(const scene::Vec3& d, double degrees) {
  const double a = degrees * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a);
  return {d.x * c + d.z * s, d.y, -d.x * s + d.z * c};
}

// One layout and method on one frame: the visibility, and (runs > 0) the median wall time of
// prefilter + reconstruct with every input resident on the device, after one untimed run (program
// builds, first allocations), as evaluate's measure() times a single map.
struct LayeredTiming {
  std::vector<float> visibility;
  double median_ms = 0, prefilter_ms = 0, reconstruct_ms = 0;
};

// A method of the comparison: one of FilterOptions, or a soft one under the scene's area light
// (its sides in world units and the plane it lies in, layer_soft_light).
struct LayeredMethod {
  std::string name;
  FilterOptions options;
  std::optional<SoftOptions> soft;
  double light_plane = 0.0;
  LayeredPipeline pipeline(const std::shared_ptr<Runtime>& rt, const CascadeSet& set) const {
    return soft ? LayeredPipeline(rt, *soft, set, light_plane) : LayeredPipeline(rt, options, set);
  }
};

bool is_soft(const std::string& name) {
  for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved})
    if (name == soft_method_name(m)) return true;
  return false;
}

// Whether a layout's layers are all unwarped (the soft methods need orthographic layers).
bool unwarped(const CascadeSet& set) {
  for (const CascadeLayer& l : set.layers)
    if (l.transform.m[12] != 0.0 || l.transform.m[13] != 0.0 || l.transform.m[14] != 0.0) return false;
  return true;
}

LayeredTiming time_layered(const std::shared_ptr<Runtime>& rt, const LayeredMethod& method, const CascadeSet& set,
                           const std::vector<HostImage>& maps, const DeviceReceivers& rx, int runs) {
  LayeredPipeline pipe = method.pipeline(rt, set);
  auto& q = rt->queue();
  const auto up = [&](const std::vector<float>& h) {
    cl::Buffer b(rt->context(), CL_MEM_READ_ONLY, std::max<size_t>(4, h.size() * sizeof(float)));
    if (!h.empty()) q.enqueueWriteBuffer(b, CL_TRUE, 0, h.size() * sizeof(float), h.data());
    return b;
  };
  std::vector<cl::Buffer> depth;
  std::vector<MapRange> ranges;
  for (const HostImage& m : maps) {
    depth.push_back(up(m.data));
    ranges.push_back(depth_range(m));
  }
  if (!pipe.soft()) pipe.set_depth_ranges(ranges);  // no device reduction inside the timed loop
  cl::Buffer vis(rt->context(), CL_MEM_WRITE_ONLY, std::max<size_t>(4, rx.count * sizeof(float)));
  std::vector<double> wall, pre, rec;
  for (int i = 0; i < 1 + runs; ++i) {
    const auto t0 = Clock::now();
    const cl::Event filtered = pipe.prefilter(depth);
    filtered.wait();
    const double pre_ms = ms_since(t0);
    const EventList after{filtered};
    pipe.reconstruct(rx, vis, &after);
    q.finish();
    if (i == 0) continue;
    wall.push_back(ms_since(t0));
    pre.push_back(pre_ms);
    rec.push_back(wall.back() - pre_ms);
  }
  LayeredTiming t;
  t.visibility.resize(rx.count);
  if (rx.count) q.enqueueReadBuffer(vis, CL_TRUE, 0, rx.count * sizeof(float), t.visibility.data());
  t.median_ms = detail::median(wall);
  t.prefilter_ms = detail::median(pre);
  t.reconstruct_ms = detail::median(rec);
  return t;
}

// Per configuration: the previous frame's set and maps (the flicker figure).
struct Previous {
  bool valid = false;
  CascadeSet set;
  std::vector<HostImage> maps;
  double light_plane = 0.0;  // the soft methods' light (LayeredMethod::light_plane)
};

}  // namespace

void check_layout_method(const std::string& name) {
  if (is_soft(name)) return;
  try {
    method(name);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + "; the soft methods pcss, cssm, ssmm, ssmm-improved");
  }
}

std::string LayoutConfig::label() const {
  std::string s;
  switch (kind) {
    case LayoutKind::Single:
      s = "single";
      break;
    case LayoutKind::Tsm:
      s = "tsm";
      break;
    case LayoutKind::Pssm:
      s = "pssm" + std::to_string(cascades);
      break;
    case LayoutKind::PssmTsm:
      s = "pssm" + std::to_string(cascades) + "+tsm";
      break;
  }
  if (!stabilize) s += " unstable";
  return s;
}

int equal_texel_side(int total_size, int layers) {
  const double side = total_size / std::sqrt(static_cast<double>(layers));
  return std::max(8, static_cast<int>(std::lround(side / 8.0)) * 8);
}

FrameMetrics frame_metrics(const std::vector<float>& v, const std::vector<float>& ref_hard,
                           const std::vector<float>& ref_soft, const std::vector<uint8_t>& mask,
                           const std::vector<uint8_t>& near) {
  FrameMetrics m;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!mask[i]) continue;
    ++m.counted;
    const double e = v[i] - ref_hard[i];
    m.sq_hard += e * e;
    if (!ref_soft.empty()) m.sq_soft += (v[i] - ref_soft[i]) * double(v[i] - ref_soft[i]);
    const bool wrong = (v[i] >= 0.5f) != (ref_hard[i] >= 0.5f);
    m.mismatched += wrong;
    if (near[i]) {
      ++m.counted_near;
      m.mismatched_near += wrong;
    }
  }
  return m;
}

double mean_abs_difference(const std::vector<float>& a, const std::vector<float>& b, const std::vector<uint8_t>& mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (mask[i]) sum += std::abs(double(a[i]) - b[i]), ++n;
  return n ? sum / n : 0.0;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

std::vector<LayoutRow> evaluate_layouts(const std::shared_ptr<Runtime>& rt, const LayoutEvalRequest& r,
                                        const std::function<void(const std::string&)>& progress) {
  if (r.scenes.empty()) throw InputError("evaluate-layouts needs a scene");
  if (r.frames < 1 || r.frames > 1000) throw InputError("--frames must lie in 1..1000");
  if (r.total_size < 8 || r.total_size > 16384) throw InputError("--total-size must lie in 8..16384");
  if (r.timing_runs < 1) throw InputError("--runs must be at least 1");
  for (const std::string& m : r.methods) check_layout_method(m);
  const std::vector<LayoutConfig> configs = make_configs(r);
  const auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  std::vector<LayoutRow> rows;
  for (const std::string& scene_name : r.scenes) {
    scene::SceneDefaults defaults = scene::is_builtin_scene(scene_name) ? scene::make_builtin_scene(scene_name)
                                                                        : scene::load_mesh_scene(scene_name);
    scene::SceneSetup setup;
    setup.geometry = defaults.geometry;
    setup.light = scene::LightView::fit_ortho(setup.geometry, defaults.light_direction, 0.01);
    setup.camera = defaults.camera;
    setup.camera.width = r.receivers_width;
    setup.camera.height = r.receivers_height;
    setup.light_size = defaults.light_size;
    setup.samples = std::max(1, r.soft_samples);
    setup.threads = r.threads;
    setup.progress = false;
    scene::CameraPathOptions path;
    path.frames = r.frames;
    path.kind = r.camera_path == "orbit" ? scene::CameraPathKind::Orbit : scene::CameraPathKind::Walk;
    path.walk_to = setup.camera.position + ((r.frames - 1) * r.walk_step) * scene::ground_ahead(setup.camera);
    path.orbit_degrees = (r.frames - 1) * r.orbit_step_degrees;
    double near_depth = defaults.camera_near, far_depth = defaults.camera_far;
    if (!(near_depth > 0.0 && far_depth > near_depth)) {
      const scene::ViewDepths depths = scene::default_view_depths(setup.camera, setup.geometry);
      near_depth = depths.near_depth;
      far_depth = depths.far_depth;
    }
    const bool light_moves = r.light_step_degrees != 0.0;
    const bool camera_moves = (path.kind == scene::CameraPathKind::Orbit ? r.orbit_step_degrees : r.walk_step) != 0.0;
    const std::vector<scene::PerspectiveCamera> cameras = scene::camera_path(setup.camera, path, far_depth);
    const std::vector<WorldBox> boxes = scene::geometry_boxes(setup.geometry);
    // Under a moving light, this frame's light and the last one's (a renderer keeps a reference
    // to its setup, so each has its own).
    auto frame_setup = std::make_unique<scene::SceneSetup>(setup);
    auto renderer = std::make_unique<scene::SceneRenderer>(*frame_setup);
    std::unique_ptr<scene::SceneSetup> last_setup;
    std::unique_ptr<scene::SceneRenderer> last_renderer;
    scene::CameraImages last_camera;

    std::map<std::string, Accumulator> acc;  // key: config label + method
    std::vector<Previous> previous(configs.size());
    for (int frame = 0; frame < r.frames; ++frame) {
      const auto t_view = Clock::now();
      if (light_moves && frame > 0) {
        last_setup = std::move(frame_setup);
        last_renderer = std::move(renderer);
        frame_setup = std::make_unique<scene::SceneSetup>(setup);
        frame_setup->light = scene::LightView::fit_ortho(
            setup.geometry, turned_about_up(defaults.light_direction, frame * r.light_step_degrees), 0.01);
        renderer = std::make_unique<scene::SceneRenderer>(*frame_setup);
      }
      const scene::SceneSetup& lit = *frame_setup;  // this frame's light
      const Point3 light_dir = scene::to_point(lit.light.forward);
      scene::CameraImages camera = renderer->camera_view(cameras[frame], r.soft_samples > 0);
      const ViewReceivers view = scene::view_receivers(camera.view);
      // The references at this frame's world points under the last frame's light (the flicker's
      // last error), when the light moves: the last frame's own when only the light moves (a
      // pixel is one world point), traced again when the camera moves too. A still light's are
      // this frame's (the scene is static).
      scene::CameraImages last_light;
      if (frame > 0 && light_moves)
        last_light = camera_moves ? last_renderer->references_at(view, cameras[frame].position, r.soft_samples > 0)
                                  : std::move(last_camera);
      say(scene_name + " frame " + std::to_string(frame) + ": camera view and references in " +
          detail::fmt(ms_since(t_view) / 1000.0, 3) + " s");
      const size_t n = view.count();
      std::vector<uint8_t> mask(n, 0), near(n, 0);
      const double near_limit = near_depth + 0.1 * (far_depth - near_depth);
      for (size_t i = 0; i < n; ++i) {
        const bool facing = view.ndl.empty() || !(view.ndl[i] <= 0.0f);
        mask[i] = std::isfinite(view.depth[i]) && facing;
        near[i] = mask[i] && view.depth[i] <= near_limit;
      }
      const std::vector<float>& hard = camera.reference_hard.data;
      static const std::vector<float> kNoSoft;
      const std::vector<float>& soft = r.soft_samples > 0 ? camera.reference_soft.data : kNoSoft;
      const CameraFrustum frustum = scene::camera_frustum(cameras[frame], near_depth, far_depth);
      // The view on the device once a frame; for the flicker figure, the same receivers with their
      // view depths in the previous frame's camera (only the depth buffer differs).
      const DeviceReceivers rx = upload_view_receivers(*rt, view);
      DeviceReceivers previous_rx = rx;
      if (frame > 0) {
        const CameraFrustum before = scene::camera_frustum(cameras[frame - 1], near_depth, far_depth);
        std::vector<float> depth(n);
        for (size_t i = 0; i < n; ++i)
          depth[i] = static_cast<float>((view.x[i] - before.position[0]) * before.forward[0] +
                                        (view.y[i] - before.position[1]) * before.forward[1] +
                                        (view.z[i] - before.position[2]) * before.forward[2]);
        previous_rx.view.depth = cl::Buffer(rt->context(), CL_MEM_READ_ONLY, std::max<size_t>(n, 1) * sizeof(float));
        if (n) rt->queue().enqueueWriteBuffer(previous_rx.view.depth, CL_TRUE, 0, n * sizeof(float), depth.data());
      }

      for (size_t c = 0; c < configs.size(); ++c) {
        const LayoutConfig& config = configs[c];
        LayoutOptions lo;
        lo.kind = config.kind;
        lo.cascades = config.cascades;
        lo.map_size = config.layer_size;
        lo.split_lambda = r.split_lambda;
        lo.tsm_focus = r.tsm_focus;
        lo.stabilize = config.stabilize;
        lo.blend = r.blend;
        const CascadeSet set = fit_layout(lo, frustum, light_dir, boxes);
        const std::vector<HostImage> maps = scene::render_layers(renderer->tracer(), set, r.threads, false);

        // Texels per pixel in the layer that serves each receiver (every 4th pixel: a quantile
        // needs no more).
        std::vector<double> texels, texels_near;
        for (size_t i = 0; i < n; i += 4) {
          if (!mask[i]) continue;
          const Point3 p{view.x[i], view.y[i], view.z[i]};
          const CascadeChoice choice = select_cascade(set, view.depth[i], p);
          if (choice.layer[0] < 0) continue;
          const double f = layer_footprint(set, choice.layer[0], p, {view.dxx[i], view.dxy[i], view.dxz[i]},
                                           {view.dyx[i], view.dyy[i], view.dyz[i]});
          texels.push_back(f);
          if (near[i]) texels_near.push_back(f);
        }

        const double texels_p10 = quantile(texels, 0.1), texels_p50 = quantile(texels, 0.5),
                     texels_p90 = quantile(texels, 0.9), texels_near_p50 = quantile(texels_near, 0.5);
        for (const std::string& method : r.methods) {
          LayeredMethod o;
          o.name = method;
          if (is_soft(method)) {
            SoftOptions so;
            so.method = find_soft_method(method);
            so.light.size = lit.light_size;
            so.light.height = lit.light_height;
            o.soft = so;
            o.light_plane = lit.light.near_plane;  // where `scene` puts the area light
            if (!unwarped(set)) {
              say(scene_name + " frame " + std::to_string(frame) + ": " + config.label() + " " + method +
                  " skipped: the soft methods need orthographic layers");
              continue;
            }
          } else {
            o.options.method = method;
            o.options.blur.radius = r.blur_radius;
            o.options.lookup.kind = r.lookup;
          }
          Accumulator& a = acc[config.label() + "|" + method];
          LayoutRow& row = a.row;
          row.scene = setup.geometry.name;
          row.layout = config.label();
          row.method = method;
          row.layers = static_cast<int>(set.layers.size());
          row.layer_size = config.layer_size;
          row.stabilize = config.stabilize;
          ++row.frames;

          const LayeredTiming timed = time_layered(rt, o, set, maps, rx, r.timing_runs);
          const FrameMetrics m = frame_metrics(timed.visibility, hard, soft, mask, near);
          a.sum.counted += m.counted;
          a.sum.counted_near += m.counted_near;
          a.sum.sq_hard += m.sq_hard;
          a.sum.sq_soft += m.sq_soft;
          a.sum.mismatched += m.mismatched;
          a.sum.mismatched_near += m.mismatched_near;
          a.times.push_back(timed.median_ms);
          a.prefilter.push_back(timed.prefilter_ms);
          a.reconstruct.push_back(timed.reconstruct_ms);
          if (!soft.empty()) ++a.frames_soft;
          row.texels_p10 += texels_p10;
          row.texels_p50 += texels_p50;
          row.texels_p90 += texels_p90;
          row.texels_near_p50 += texels_near_p50;
          if (previous[c].valid) {
            // The same world points (this frame's receivers) through last frame's layers and
            // light, each picking its layer by its view depth in last frame's camera: what the
            // previous frame showed there. On a static scene under a still light the reference
            // does not change at a world point, so every difference is the layout's (texels
            // moving, receivers changing layers); under a moving light the error's change is.
            LayeredMethod last = o;
            last.light_plane = previous[c].light_plane;
            const LayeredTiming before = time_layered(rt, last, previous[c].set, previous[c].maps, previous_rx, 0);
            const bool against_soft = o.soft && !soft.empty();
            const std::vector<float>& ref = against_soft ? soft : hard;
            const std::vector<float>& ref_last = !light_moves   ? ref
                                                 : against_soft ? last_light.reference_soft.data
                                                                : last_light.reference_hard.data;
            a.flicker_sum += mean_error_change(timed.visibility, ref, before.visibility, ref_last, mask);
            ++a.flicker_pairs;
          }
        }
        previous[c] = {true, set, maps, lit.light.near_plane};
        say(scene_name + " frame " + std::to_string(frame) + ": " + config.label() + " done");
      }
      if (light_moves && !camera_moves) last_camera = std::move(camera);
    }
    for (const LayoutConfig& config : configs) {
      for (const std::string& method : r.methods) {
        if (!acc.count(config.label() + "|" + method)) continue;  // skipped on every frame
        Accumulator& a = acc[config.label() + "|" + method];
        LayoutRow row = a.row;
        const double frames = std::max(1, row.frames);
        row.counted = static_cast<size_t>(a.sum.counted / frames);
        row.counted_near = static_cast<size_t>(a.sum.counted_near / frames);
        row.rmse_hard = a.sum.counted ? std::sqrt(a.sum.sq_hard / a.sum.counted) : 0.0;
        row.rmse_soft = a.frames_soft && a.sum.counted ? std::sqrt(a.sum.sq_soft / a.sum.counted) : -1.0;
        row.mismatch = a.sum.counted ? a.sum.mismatched / a.sum.counted : 0.0;
        row.mismatch_near = a.sum.counted_near ? a.sum.mismatched_near / a.sum.counted_near : 0.0;
        row.texels_p10 /= frames;
        row.texels_p50 /= frames;
        row.texels_p90 /= frames;
        row.texels_near_p50 /= frames;
        row.flicker = a.flicker_pairs ? a.flicker_sum / a.flicker_pairs : -1.0;
        row.time_ms = detail::median(a.times);
        row.prefilter_ms = detail::median(a.prefilter);
        row.reconstruct_ms = detail::median(a.reconstruct);
        rows.push_back(row);
      }
    }
  }
  return rows;
}

void write_layout_csv(const std::string& path, const std::vector<LayoutRow>& rows) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << "scene,layout,method,layers,layer_size,stabilize,frames,receivers,rmse_hard,rmse_soft,mismatch,"
         "mismatch_near,receivers_near,texels_p10,texels_p50,texels_p90,texels_near_p50,flicker,time_ms,"
         "prefilter_ms,reconstruct_ms\n";
  for (const LayoutRow& w : rows)
    out << w.scene << ',' << w.layout << ',' << w.method << ',' << w.layers << ',' << w.layer_size << ','
        << (w.stabilize ? 1 : 0) << ',' << w.frames << ',' << w.counted << ',' << w.rmse_hard << ',' << w.rmse_soft
        << ',' << w.mismatch << ',' << w.mismatch_near << ',' << w.counted_near << ',' << w.texels_p10 << ','
        << w.texels_p50 << ',' << w.texels_p90 << ',' << w.texels_near_p50 << ',' << w.flicker << ',' << w.time_ms
        << ',' << w.prefilter_ms << ',' << w.reconstruct_ms << '\n';
  io::write_text(path, "results file", out.str());
}

std::string layout_markdown(const std::vector<LayoutRow>& rows) {
  using detail::fmt;
  std::ostringstream out;
  out << "| scene | layout | method | layers | ms/frame | mismatched | mismatched, nearest 10% | RMSE hard | "
         "RMSE soft | texels/pixel p10 / p50 / p90 (nearest 10%: p50) | flicker |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const LayoutRow& w : rows)
    out << "| " << w.scene << " | " << w.layout << " | " << w.method << " | " << w.layers << " x " << w.layer_size
        << "² | " << fmt(w.time_ms, 4) << " | " << fmt(100 * w.mismatch, 3) << "% | " << fmt(100 * w.mismatch_near, 3)
        << "% | " << fmt(w.rmse_hard, 3) << " | " << (w.rmse_soft < 0 ? std::string("-") : fmt(w.rmse_soft, 3)) << " | "
        << fmt(w.texels_p10, 2) << " / " << fmt(w.texels_p50, 2) << " / " << fmt(w.texels_p90, 2) << " ("
        << fmt(w.texels_near_p50, 2) << ") | " << (w.flicker < 0 ? std::string("-") : fmt(w.flicker, 3)) << " |\n";
  return out.str();
}

void write_layout_plot(const std::string& path, const std::vector<LayoutRow>& rows, const std::string& scene) {
  namespace IBA = OIIO::ImageBufAlgo;
  std::vector<std::string> layouts, methods;
  const auto add = [](std::vector<std::string>& list, const std::string& s) {
    if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
  };
  for (const LayoutRow& w : rows)
    if (w.scene == scene) add(layouts, w.layout), add(methods, w.method);
  const auto find = [&](const std::string& layout, const std::string& method) -> const LayoutRow* {
    for (const LayoutRow& w : rows)
      if (w.scene == scene && w.layout == layout && w.method == method) return &w;
    return nullptr;
  };
  // Two panels side by side: mismatched pixels in the nearest 10% and flicker, one group of bars
  // per layout, one bar per method in its colour.
  const int W = 1260, H = 540, T = 80, B = 84, panel_w = 560, gap = 80, L = 50;
  OIIO::ImageBuf img(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::FLOAT));
  IBA::fill(img, {1.0f, 1.0f, 1.0f});
  const std::vector<float> black{0, 0, 0}, grey{0.85f, 0.85f, 0.85f};
  const std::string title = scene + ": layouts at equal total texels";
  draw::text(img, 12, 26, title, black, 17);
  struct Panel {
    std::string name;
    double (*value)(const LayoutRow&);
  };
  const Panel panels[2] = {{"mismatched pixels against reference_hard, nearest 10% of the view (%)",
                            [](const LayoutRow& w) { return 100.0 * w.mismatch_near; }},
                           {"flicker: mean |e(t) - e(t-1)|, e = v - reference, at the same world points (x 1e-3)",
                            [](const LayoutRow& w) { return w.flicker < 0 ? 0.0 : 1000.0 * w.flicker; }}};
  for (int p = 0; p < 2; ++p) {
    const int x0 = L + p * (panel_w + gap), x1 = x0 + panel_w, y0 = T, y1 = H - B;
    double vmax = 0;
    for (const LayoutRow& w : rows)
      if (w.scene == scene) vmax = std::max(vmax, panels[p].value(w));
    vmax = vmax > 0 ? vmax * 1.1 : 1.0;
    draw::text(img, x0, y0 - 14, panels[p].name, black, 12);
    for (int k = 0; k <= 4; ++k) {
      const int y = y1 - k * (y1 - y0) / 4;
      IBA::render_line(img, x0, y, x1, y, grey);
      draw::text(img, x0 - 36, y + 4, detail::fmt(vmax * k / 4, 2), black, 11);
    }
    const int group = panel_w / std::max<size_t>(1, layouts.size());
    const int bar = std::max(4, (group - 16) / static_cast<int>(std::max<size_t>(1, methods.size())));
    for (size_t g = 0; g < layouts.size(); ++g) {
      const int gx = x0 + static_cast<int>(g) * group + 8;
      for (size_t m = 0; m < methods.size(); ++m) {
        const LayoutRow* w = find(layouts[g], methods[m]);
        if (!w) continue;
        const int h = static_cast<int>(panels[p].value(*w) / vmax * (y1 - y0));
        IBA::fill(img, draw::method_colour(methods[m]),
                  OIIO::ROI(gx + static_cast<int>(m) * bar, gx + static_cast<int>(m + 1) * bar - 2, y1 - h, y1));
      }
      draw::text(img, gx, y1 + 18 + static_cast<int>(g % 2) * 15, layouts[g], black, 12);  // staggered
    }
    IBA::render_box(img, x0, y0, x1, y1, black);
  }
  for (size_t m = 0; m < methods.size(); ++m) {
    const int x = L + static_cast<int>(m) * 120;
    IBA::fill(img, draw::method_colour(methods[m]), OIIO::ROI(x, x + 14, H - 30, H - 16));
    draw::text(img, x + 20, H - 17, methods[m], black, 13);
  }
  draw::write_png8(path, img, title);
}

}  // namespace sf::eval

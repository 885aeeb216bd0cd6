#include "evaluate.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <thread>

#include "image_io.hpp"
#include "lookups.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {
namespace fs = std::filesystem;

namespace {

// First channel of a camera-view reference image (half EXR), or an empty image.
HostImage load_reference(const std::string& path) {
  HostImage img;
  if (!fs::exists(path)) return img;
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError("cannot open reference '" + path + "': " + OIIO::geterror());
  const auto& spec = in->spec();
  std::vector<float> all(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw InputError("cannot read reference '" + path + "': " + in->geterror());
  img = HostImage(spec.width, spec.height, 1);
  for (size_t i = 0; i < img.texels(); ++i) img.data[i] = all[i * spec.nchannels];
  return img;
}

void analyse(Scene& s) {
  const Receivers& rx = s.receivers;
  s.valid.assign(rx.count(), 0);
  s.valid_count = 0;
  s.max_footprint = 1.0;
  for (size_t i = 0; i < rx.count(); ++i) {
    if (!std::isfinite(rx.d[i])) continue;
    if (!rx.grid && !(rx.u[i] >= 0.0f && rx.u[i] <= 1.0f && rx.v[i] >= 0.0f && rx.v[i] <= 1.0f)) continue;
    s.valid[i] = 1;
    ++s.valid_count;
    if (!rx.grid && rx.has_footprint && std::isfinite(rx.f[i]))
      s.max_footprint = std::max(s.max_footprint, double(rx.f[i]));
  }
}

template <typename T>
double median(std::vector<T> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? double(v[n / 2]) : 0.5 * (double(v[n / 2 - 1]) + double(v[n / 2]));
}

std::string fmt(double v, int prec = 4) {
  std::ostringstream s;
  s.precision(prec);
  s << v;
  return s.str();
}

}  // namespace

Scene make_scene(std::string name, HostImage depth, Receivers receivers) {
  Scene s;
  s.name = std::move(name);
  s.depth = std::move(depth);
  s.receivers = std::move(receivers);
  analyse(s);
  return s;
}

Scene load_scene(const std::string& dir) {
  const fs::path p(dir);
  if (!fs::is_directory(p)) throw InputError("scene directory '" + dir + "' does not exist");
  for (const char* f : {"shadowmap.exr", "receivers.exr"})
    if (!fs::exists(p / f)) throw InputError("scene directory '" + dir + "' has no " + f);
  Scene s = make_scene(fs::absolute(p).lexically_normal().filename().string(),
                       io::load_depth_map((p / "shadowmap.exr").string(), {}),
                       io::load_receiver_image((p / "receivers.exr").string()));
  if (s.name.empty()) s.name = fs::absolute(p).lexically_normal().parent_path().filename().string();
  s.dir = dir;
  s.ref_hard = load_reference((p / "reference_hard.exr").string());
  s.ref_soft = load_reference((p / "reference_soft.exr").string());
  for (const HostImage* r : {&s.ref_hard, &s.ref_soft})
    if (r->width && (r->width != s.receivers.width || r->height != s.receivers.height))
      throw InputError("scene '" + dir + "': reference size differs from the receivers'");
  return s;
}

// --- grid -----------------------------------------------------------------------------------------

Grid parse_grid(const std::string& name) {
  if (name == "quick") return Grid::Quick;
  if (name == "default") return Grid::Default;
  if (name == "wide") return Grid::Wide;
  throw InputError("--grid must be quick, default or wide, got '" + name + "'");
}

std::vector<std::string> parse_methods(const std::string& list) {
  std::vector<std::string> out;
  if (list == "all" || list.empty()) {
    for (const auto& m : methods()) out.push_back(m.name);
    return out;
  }
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    find_method(item);  // throws naming the known methods
    if (std::find(out.begin(), out.end(), item) == out.end()) out.push_back(item);
  }
  if (out.empty()) throw InputError("--methods lists no method");
  return out;
}

std::string config_label(const FilterOptions& o) {
  std::ostringstream s;
  s << o.method;
  const MethodDesc& m = find_method(o.method);
  if (o.method == "esm") s << " c=" << o.esm.c;
  if (o.method == "vsm" || o.method.rfind("evsm", 0) == 0) {
    if (o.vsm.lbr > 0) s << " lbr=" << o.vsm.lbr;
  }
  if (o.method.rfind("evsm", 0) == 0) s << " c+=" << o.evsm.pos;
  if (o.method == "csm") s << " M=" << o.csm.order;
  if (o.method != "sm") s << " R=" << o.blur.radius;
  if (!m.raw_depth) {
    if (o.lookup.kind == Lookup::Mips) s << " mips";
    if (o.lookup.kind == Lookup::Sat) s << " sat";
    s << " " << storage_name(o.storage);
  }
  if (o.esm_classify.mode == EsmClassify::ZMax) s << " zmax";
  if (o.esm_classify.mode == EsmClassify::Threshold) s << " threshold";
  return s.str();
}

std::vector<FilterOptions> make_grid(const std::vector<std::string>& names, Grid grid,
                                     double max_footprint, double sref_bias) {
  const bool quick = grid == Grid::Quick, wide = grid == Grid::Wide;
  std::vector<int> radii = quick ? std::vector<int>{1, 3} : wide ? std::vector<int>{0, 1, 3, 7, 15}
                                                                 : std::vector<int>{0, 1, 3, 7};
  std::vector<Lookup> lookups{Lookup::Bilinear};
  if (max_footprint > 1.0) {
    lookups.push_back(Lookup::Mips);
    if (!quick) lookups.push_back(Lookup::Sat);
  }
  std::vector<FilterOptions> out;
  auto add = [&out](FilterOptions o) { out.push_back(o); };
  for (const auto& name : names) {
    const MethodDesc& m = find_method(name);
    FilterOptions base;
    base.method = name;
    if (m.raw_depth) base.depth_test.bias = float(sref_bias);
    if (name == "sm") {
      add(base);
      continue;
    }
    if (name == "pcf") {
      for (int r : quick ? std::vector<int>{1, 3} : radii) {
        FilterOptions o = base;
        o.blur.radius = r;
        add(o);
      }
      continue;
    }
    // Per-method parameter variants (each then crossed with radii and lookups).
    std::vector<FilterOptions> variants;
    if (name == "esm") {
      for (float c : quick ? std::vector<float>{40, 80} : wide ? std::vector<float>{20, 40, 80, 120, 160}
                                                             : std::vector<float>{40, 80, 160}) {
        FilterOptions o = base;
        o.esm.c = c;
        variants.push_back(o);
      }
    } else if (name == "vsm") {
      for (float a : quick ? std::vector<float>{0.0f, 0.2f} : std::vector<float>{0.0f, 0.2f, 0.4f}) {
        FilterOptions o = base;
        o.vsm.lbr = a;
        variants.push_back(o);
      }
    } else if (name == "csm") {
      for (int M : quick ? std::vector<int>{4, 8} : wide ? std::vector<int>{1, 2, 4, 8, 16, 32}
                                                             : std::vector<int>{2, 4, 8, 16}) {
        FilterOptions o = base;
        o.csm.order = M;
        variants.push_back(o);
      }
    } else if (name.rfind("evsm", 0) == 0 && wide) {
      for (float c : {20.0f, 40.0f}) {
        FilterOptions o = base;
        o.evsm.pos = c;
        variants.push_back(o);
      }
    } else {
      variants.push_back(base);
    }
    for (const auto& v : variants)
      for (int r : radii)
        for (Lookup lk : lookups) {
          if (quick && lk != Lookup::Bilinear && !(name == "esm" || name == "csm")) continue;
          FilterOptions o = v;
          o.blur.radius = r;
          o.lookup.kind = lk;
          add(o);
        }
    // Storage formats other than f32, without and with a prefilter (what the pipeline refuses is
    // reported as skipped).
    if (!quick) {
      std::stringstream st(m.storages);
      std::string s;
      while (st >> s) {
        if (s == "f32") continue;
        FilterOptions o = variants.front();
        o.storage = parse_storage(s);
        if (name == "esm" && o.storage == Storage::F16) o.esm.c = 20;  // f16 holds c <= 22
        o.blur.radius = 0;
        add(o);
        o.blur.radius = 3;
        add(o);
      }
    }
  }
  return out;
}

// --- errors ----------------------------------------------------------------------------------------

ErrorStats error_stats(const std::vector<float>& v, const std::vector<double>& ref,
                       const std::vector<uint8_t>& mask) {
  ErrorStats e;
  if (ref.size() != v.size() || mask.size() != v.size()) return e;
  std::vector<float> abs_err;
  abs_err.reserve(v.size());
  double sq = 0;
  size_t over1 = 0, over5 = 0, leak = 0, dark = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!mask[i]) continue;
    const double diff = double(v[i]) - ref[i];
    const double a = std::isfinite(diff) ? std::abs(diff) : 1.0;  // NaN counts as the worst error
    abs_err.push_back(float(a));
    sq += a * a;
    over1 += a > 1.0 / 255.0;
    over5 += a > 0.05;
    leak += diff > 0.05;
    dark += diff < -0.05;
  }
  e.n = abs_err.size();
  if (e.n == 0) return e;
  e.valid = true;
  const double n = double(e.n);
  e.rmse = std::sqrt(sq / n);
  e.max = *std::max_element(abs_err.begin(), abs_err.end());
  // p99: the smallest error that at least 99% of the receivers stay at or under.
  const size_t k = std::min(e.n - 1, size_t(std::ceil(0.99 * n)) - 1);
  std::nth_element(abs_err.begin(), abs_err.begin() + k, abs_err.end());
  e.p99 = abs_err[k];
  e.frac_1_255 = over1 / n;
  e.frac_005 = over5 / n;
  e.leak = leak / n;
  e.darken = dark / n;
  return e;
}

void check_metric(const std::string& m) {
  static const char* names[] = {"rmse", "p99", "max", "frac_1_255", "frac_005", "leak", "darken"};
  for (const char* n : names)
    if (m == n) return;
  throw InputError("unknown error metric '" + m + "' (known: rmse, p99, max, frac_1_255, frac_005, leak, darken)");
}

double metric_value(const ErrorStats& e, const std::string& m) {
  check_metric(m);
  if (m == "rmse") return e.rmse;
  if (m == "p99") return e.p99;
  if (m == "max") return e.max;
  if (m == "frac_1_255") return e.frac_1_255;
  if (m == "frac_005") return e.frac_005;
  if (m == "leak") return e.leak;
  return e.darken;
}

double row_metric(const Row& r, const std::string& metric) {
  if (metric.rfind("hard_", 0) == 0) return metric_value(r.hard, metric.substr(5));
  if (metric.rfind("soft_", 0) == 0) return metric_value(r.soft, metric.substr(5));
  return metric_value(r.sref, metric);
}

// --- s_ref -----------------------------------------------------------------------------------------

std::vector<double> s_ref_parallel(const HostImage& depth, const BlurOptions& blur, Lookup lookup,
                                   const Receivers& rx, double bias) {
  const size_t n = rx.count();
  std::vector<double> out(n, 1.0);
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, n / 4096)));
  auto work = [&](size_t t) {
    for (size_t i = t; i < n; i += threads) {
      const double u = rx.grid ? ref::texel_centre(int(i % rx.width), rx.width) : rx.u[i];
      const double v = rx.grid ? ref::texel_centre(int(i / rx.width), rx.height) : rx.v[i];
      out[i] = ref::s_ref(depth, blur, lookup, u, v, rx.d[i], ref::footprint_at(rx, i), bias);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  return out;
}

const std::vector<double>& SrefCache::get(const BlurOptions& blur, Lookup lookup) {
  const float sigma = blur.radius > 0 ? (blur.sigma > 0 ? blur.sigma : float((2 * blur.radius + 1) / 6.0)) : 0.0f;
  const std::string key = std::to_string(blur.radius) + "/" + std::to_string(sigma) + "/" +
                          std::to_string(int(lookup));
  auto it = cache_.find(key);
  if (it != cache_.end()) return it->second;
  return cache_[key] = s_ref_parallel(scene_.depth, blur, lookup, scene_.receivers, bias_);
}

const std::vector<double>& SrefCache::for_options(const FilterOptions& o) {
  const MethodDesc& m = find_method(o.method);
  BlurOptions blur = o.blur;
  if (o.method == "sm") blur = BlurOptions{};
  return get(blur, m.raw_depth ? Lookup::Bilinear : o.lookup.kind);
}

// --- timing ----------------------------------------------------------------------------------------

Measured measure(const std::shared_ptr<Runtime>& rt, const FilterOptions& o, const Scene& scene,
                 const TimingSettings& t) {
  using Clock = std::chrono::steady_clock;
  const Receivers& r = scene.receivers;
  Pipeline pipe(rt, o, scene.depth.width, scene.depth.height);  // validates, may throw InputError
  auto& q = rt->queue();
  auto up = [&](const std::vector<float>& h) {
    cl::Buffer b(rt->context(), CL_MEM_READ_ONLY, std::max<size_t>(4, h.size() * sizeof(float)));
    if (!h.empty()) q.enqueueWriteBuffer(b, CL_TRUE, 0, h.size() * sizeof(float), h.data());
    return b;
  };
  const size_t count = r.count();
  cl::Buffer depth = up(scene.depth.data);
  DeviceReceivers rx;
  rx.grid = r.grid;
  rx.count = count;
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
  cl::Buffer vis(rt->context(), CL_MEM_WRITE_ONLY, std::max<size_t>(4, count * sizeof(float)));

  Measured m;
  std::vector<double> wall, tr, bl, rc, py, sa, zm, cls;
  for (int i = 0; i < t.warmup + std::max(1, t.runs); ++i) {
    const auto t0 = Clock::now();
    cl::Event f = pipe.prefilter(depth);
    EventList after{f};
    pipe.reconstruct(rx, vis, &after);
    q.finish();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (i < t.warmup) continue;
    wall.push_back(ms);
    const StageTimes s = pipe.times();
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
  m.visibility.resize(count);
  if (count) q.enqueueReadBuffer(vis, CL_TRUE, 0, count * sizeof(float), m.visibility.data());
  m.device_bytes = pipe.device_bytes() + scene.depth.data.size() * sizeof(float) + rx_bytes +
                   count * sizeof(float);
  return m;
}

// A result row's identity and timings; the caller adds the errors it needs.
static Row timed_row(const Scene& scene, const FilterOptions& o, const Measured& m) {
  Row row;
  row.scene = scene.name;
  row.method = o.method;
  row.label = config_label(o);
  row.options = o;
  row.time_ms = m.median_ms;
  row.min_ms = m.min_ms;
  row.stages = m.stages;
  row.device_bytes = m.device_bytes;
  row.runs = m.runs;
  return row;
}

Row evaluate_config(const std::shared_ptr<Runtime>& rt, const Scene& scene, const FilterOptions& o,
                    SrefCache& sref, const TimingSettings& t) {
  Measured m = measure(rt, o, scene, t);
  Row row = timed_row(scene, o, m);
  row.sref = error_stats(m.visibility, sref.for_options(o), scene.valid);
  auto vs_image = [&](const HostImage& img) {
    if (img.texels() != m.visibility.size()) return ErrorStats{};
    return error_stats(m.visibility, std::vector<double>(img.data.begin(), img.data.end()), scene.valid);
  };
  row.hard = vs_image(scene.ref_hard);
  row.soft = vs_image(scene.ref_soft);
  row.visibility = std::move(m.visibility);
  return row;
}

// --- pareto -----------------------------------------------------------------------------------------

std::vector<size_t> pareto_front(const std::vector<Row>& rows, const std::string& metric) {
  std::vector<size_t> idx(rows.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](size_t a, size_t b) {
    if (rows[a].time_ms != rows[b].time_ms) return rows[a].time_ms < rows[b].time_ms;
    return row_metric(rows[a], metric) < row_metric(rows[b], metric);
  });
  std::vector<size_t> front;
  double best = INFINITY;
  for (size_t i : idx) {
    const double e = row_metric(rows[i], metric);
    if (e < best) {
      front.push_back(i);
      best = e;
    }
  }
  return front;
}

// --- --auto -----------------------------------------------------------------------------------------

double estimated_cost(const FilterOptions& o, int map_w, int map_h, size_t receivers) {
  // Rough nanoseconds on the development machine (2 cores, PoCL; quick grid in docs/results.md):
  // per map texel for the prefilter stages, per receiver for the reconstruction.
  const MethodDesc& m = find_method(o.method);
  const double T = double(map_w) * map_h, N = double(receivers);
  if (m.raw_depth) {
    if (o.method == "sm") return 1e-6 * N * 9.0;
    const double side = 2.0 * o.blur.radius + 2.0;  // pcf reads every texel of the support
    return 1e-6 * N * (8.0 + 1.2 * side * side);
  }
  const int ch = m.channels(o);
  const double bytes = double(basis_bytes_per_texel(m, o));
  double texel = 0.5 * ch * (o.method == "csm" ? 2.0 : 1.0);  // transform
  if (o.blur.radius > 0) texel += 0.25 * bytes * (1.0 + o.blur.radius / 8.0);
  if (o.lookup.kind == Lookup::Mips) texel += 0.1 * bytes;
  if (o.lookup.kind == Lookup::Sat) texel += 0.5 * bytes + 0.5 * ch;
  double rx = 9.0;  // vsm, evsm2: one Chebyshev bound
  if (o.method == "esm") rx = 25.0;  // log-space exp
  if (o.method == "evsm4") rx = 40.0;
  if (o.method == "msm") rx = 60.0;  // Hamburger: Cholesky + cubic
  if (o.method == "msm-hausdorff") rx = 50.0;
  if (o.method == "csm") rx = 6.0 * ch;
  if (o.lookup.kind == Lookup::Mips) rx *= 2.0;  // two bilinear levels
  if (o.lookup.kind == Lookup::Sat) rx *= 2.5;   // four float-float corners
  if (o.esm_classify.mode == EsmClassify::Threshold) rx += 6.0;
  if (o.esm_classify.mode == EsmClassify::ZMax) {
    texel += 0.4;  // the z-max pyramid of the depth
    rx += 10.0;
  }
  return 1e-6 * (T * texel + N * rx);
}

std::vector<AutoCandidate> auto_candidates(const Scene& scene, const AutoRequest& req, const FilterOptions& target,
                                           std::vector<Skipped>* refused) {
  const std::vector<std::string> names = req.methods.empty() ? parse_methods("all") : req.methods;
  std::vector<Lookup> lookups{Lookup::Bilinear};
  if (target.lookup.kind != Lookup::Bilinear) lookups.push_back(target.lookup.kind);
  std::vector<FilterOptions> all;
  for (const auto& name : names) {
    const MethodDesc& m = find_method(name);
    FilterOptions base = target;
    base.method = name;
    base.esm_classify = EsmClassifyOptions{};
    base.lookup.kind = Lookup::Bilinear;
    if (m.raw_depth) {
      base.depth_test.bias = float(req.sref_bias);
      all.push_back(base);  // sm / pcf: no basis, no lookup (they follow no footprint)
      continue;
    }
    std::vector<Storage> storages;
    {
      std::stringstream ss(m.storages);
      std::string st;
      while (ss >> st) storages.push_back(parse_storage(st));
    }
    std::vector<FilterOptions> params;
    auto variant = [&](auto&& set) {
      FilterOptions o = base;
      set(o);
      params.push_back(o);
    };
    if (name == "esm") {
      for (float c : {20.0f, 40.0f, 80.0f, 160.0f})
        for (EsmClassify k : {EsmClassify::None, EsmClassify::Threshold, EsmClassify::ZMax})
          variant([&](FilterOptions& o) {
            o.esm.c = c;
            o.esm_classify.mode = k;
          });
    } else if (name == "vsm") {
      for (float a : {0.0f, 0.2f, 0.4f}) variant([&](FilterOptions& o) { o.vsm.lbr = a; });
    } else if (name == "evsm2" || name == "evsm4") {
      for (float c : {20.0f, 40.0f}) variant([&](FilterOptions& o) { o.evsm.pos = c; });
    } else if (name == "csm") {
      for (int M : {1, 2, 4, 8, 16, 32}) variant([&](FilterOptions& o) { o.csm.order = M; });
    } else {
      params.push_back(base);
    }
    for (const auto& p : params)
      for (Storage st : storages)
        for (Lookup lk : lookups) {
          FilterOptions o = p;
          o.storage = st;
          o.lookup.kind = lk;
          // evsm's warp is clamped to 5.54 in f16: the c+ variants are one configuration there.
          if (st == Storage::F16 && name.rfind("evsm", 0) == 0 && p.evsm.pos != 20.0f) continue;
          if (st == Storage::F16 && name == "esm" && p.esm.c > 20.0f) continue;  // f16 holds c <= 22
          try {
            m.validate(o);
          } catch (const InputError& e) {
            if (refused) refused->push_back({scene.name, config_label(o), e.what()});
            continue;
          }
          all.push_back(o);
        }
  }
  std::vector<AutoCandidate> out;
  for (const auto& o : all)
    out.push_back({o, estimated_cost(o, scene.depth.width, scene.depth.height, scene.valid_count)});
  std::stable_sort(out.begin(), out.end(),
                   [](const AutoCandidate& a, const AutoCandidate& b) { return a.cost < b.cost; });
  return out;
}

TimedChoice choose_by_times(const std::vector<std::vector<double>>& rounds, const std::vector<double>& cost,
                            double time_tolerance) {
  if (rounds.empty() || cost.empty()) throw InputError("choose_by_times: no rounds or no finalists");
  const size_t n = cost.size();
  std::vector<std::vector<double>> ratio(n);  // ratio[k]: finalist k's time over the round's fastest
  for (const auto& t : rounds) {
    if (t.size() != n) throw InputError("choose_by_times: a round has " + std::to_string(t.size()) +
                                        " times for " + std::to_string(n) + " finalists");
    const double best = *std::min_element(t.begin(), t.end());
    for (size_t k = 0; k < n; ++k) ratio[k].push_back(t[k] / best);
  }
  TimedChoice c;
  std::vector<double> noise;
  for (size_t k = 0; k < n; ++k) {
    c.score.push_back(median(ratio[k]));
    noise.push_back(c.score[k] / *std::min_element(ratio[k].begin(), ratio[k].end()) - 1.0);
  }
  c.noise = n > 1 ? median(noise) : 0.0;
  c.tolerance = std::max(time_tolerance, c.noise);
  c.order.resize(n);
  for (size_t k = 0; k < n; ++k) c.order[k] = k;
  std::stable_sort(c.order.begin(), c.order.end(), [&](size_t a, size_t b) { return c.score[a] < c.score[b]; });
  const double best = c.score[c.order.front()];
  c.pick = c.order.front();
  for (size_t k : c.order)
    if (c.score[k] <= best * (1.0 + c.tolerance) && cost[k] < cost[c.pick]) c.pick = k;
  return c;
}

// The choice among the candidates under the bound (`hits`, indices in res.tried). One run's time
// on a loaded machine is off by tens of percent, and a short quiet moment can make one
// candidate's fastest run half the others', so the finalists run again in interleaved rounds and
// are compared within each round (choose_by_times: the median over the rounds of a finalist's
// time over the round's fastest, ties within the measured noise to the lowest estimate), which
// makes the choice repeatable. Finalists: the hits whose first pass is within 3x of the fastest,
// at most 8.
static void choose_measured(const std::shared_ptr<Runtime>& rt, const Scene& scene, const AutoRequest& req,
                            const std::vector<size_t>& hits, AutoResult& res) {
  constexpr size_t kMaxFinalists = 8;
  std::vector<size_t> fin = hits;
  std::stable_sort(fin.begin(), fin.end(), [&](size_t a, size_t b) { return res.tried[a].min_ms < res.tried[b].min_ms; });
  const double first_best = res.tried[fin.front()].min_ms;
  while (fin.size() > kMaxFinalists || res.tried[fin.back()].min_ms > 3.0 * first_best) fin.pop_back();
  std::vector<std::vector<double>> rounds;  // the fastest run of each finalist per round
  const TimingSettings t{1, std::max(1, req.timing.runs)};
  for (int round = 0; round < req.final_rounds && fin.size() > 1; ++round) {
    std::vector<double> pass(fin.size());
    for (size_t j = 0; j < fin.size(); ++j) {
      const size_t k = (j + size_t(round)) % fin.size();  // rotate: no fixed position in a round
      Row& row = res.tried[fin[k]];
      pass[k] = measure(rt, row.options, scene, t).min_ms;
      row.min_ms = std::min(row.min_ms, pass[k]);
      row.runs += t.runs;
    }
    rounds.push_back(pass);
  }
  if (rounds.empty()) {  // no rounds: the first pass decides
    rounds.emplace_back();
    for (size_t i : fin) rounds.back().push_back(res.tried[i].min_ms);
  }
  std::vector<double> cost;
  for (size_t i : fin) cost.push_back(res.tried_cost[i]);
  const TimedChoice c = choose_by_times(rounds, cost, req.time_tolerance);
  res.noise = c.noise;
  res.tolerance = c.tolerance;
  for (size_t k : c.order) {
    const Row& row = res.tried[fin[k]];
    res.finalists.push_back({row.label, row.min_ms, c.score[k], cost[k]});
  }
  const size_t pick = c.pick, fastest = c.order.front();
  if (pick != fastest)
    res.tie = res.tried[fin[fastest]].label + " scored " + fmt(100.0 * (c.score[pick] / c.score[fastest] - 1.0), 2) +
              "% faster, within the " + fmt(100.0 * res.tolerance, 2) + "% band, and has a higher estimate";
  res.chosen = res.tried[fin[pick]].options;
  res.chosen_row = res.tried[fin[pick]];
  res.chosen_score = c.score[pick];
}

AutoResult choose_auto(const std::shared_ptr<Runtime>& rt, const Scene& scene, const AutoRequest& req,
                       const std::function<void(size_t, size_t)>& progress) {
  check_metric(req.metric);
  if (!(req.max_error >= 0)) throw InputError("--max-error must be a non-negative number");
  if (!(req.cost_slack >= 1)) throw InputError("--auto cost slack must be >= 1");
  if (req.final_rounds < 0 || !(req.time_tolerance >= 0)) throw InputError("--auto final rounds and tolerance must be >= 0");
  AutoResult res;
  FilterOptions target = req.target;
  if (req.lookup_from_scene) target.lookup.kind = scene.max_footprint > 1.0 ? Lookup::Mips : Lookup::Bilinear;
  // Mips / SAT with every footprint <= 1 read level 0 with the bilinear (mips: LOD 0) or unit-box
  // (= bilinear) weights: the table would only cost time.
  if (scene.max_footprint <= 1.0) {
    const bool asked = target.lookup.kind != Lookup::Bilinear;
    res.skipped.push_back(std::string(asked && target.lookup.kind == Lookup::Sat ? "summed-area table" : "mip pyramid") +
                          ": every footprint is <= 1 texel (max " + fmt(scene.max_footprint) +
                          "), so the lookup equals bilinear");
    target.lookup.kind = Lookup::Bilinear;
  }
  res.target = target;
  res.notes.push_back("target: s_ref with " +
                      std::string(target.blur.radius > 0 ? "Gaussian R=" + std::to_string(target.blur.radius) : "no prefilter") +
                      (target.lookup.kind == Lookup::Mips ? ", trilinear mips" : target.lookup.kind == Lookup::Sat ? ", box (sat)" : ", bilinear") +
                      ", depth bias " + fmt(req.sref_bias) + "; " + req.metric + " <= " + fmt(req.max_error) +
                      " over " + std::to_string(scene.valid_count) + " receivers (max footprint " +
                      fmt(scene.max_footprint) + " texels)");
  SrefCache cache(scene, req.sref_bias);
  const std::vector<double>& sref = cache.get(target.blur, target.lookup.kind);

  const std::vector<AutoCandidate> cands = auto_candidates(scene, req, target, &res.refused);
  std::vector<size_t> hits;  // indices in res.tried of the candidates under the bound
  double limit = INFINITY;   // measure up to cost_slack x the first hit's estimate
  size_t done = 0;
  for (const auto& c : cands) {
    if (c.cost > limit) {
      res.not_tried.push_back(c);
      continue;
    }
    Row row;
    try {
      Measured m = measure(rt, c.options, scene, req.timing);
      row = timed_row(scene, c.options, m);
      row.sref = error_stats(m.visibility, sref, scene.valid);
    } catch (const InputError& e) {
      res.refused.push_back({scene.name, config_label(c.options), e.what()});
      if (progress) progress(++done, cands.size());
      continue;
    }
    if (progress) progress(++done, cands.size());
    res.tried.push_back(row);
    res.tried_cost.push_back(c.cost);
    if (metric_value(row.sref, req.metric) > req.max_error) continue;
    if (res.first_hit.empty()) {
      res.first_hit = row.label;
      limit = c.cost * req.cost_slack;
    }
    hits.push_back(res.tried.size() - 1);
  }
  if (progress) progress(cands.size(), cands.size());
  if (!hits.empty()) {
    choose_measured(rt, scene, req, hits, res);
    res.found = true;
  }
  // What the choice does without, and why.
  bool any_zmax = false;
  for (const auto& c : cands) any_zmax |= c.options.esm_classify.mode == EsmClassify::ZMax;
  if (!res.found || res.chosen.esm_classify.mode != EsmClassify::ZMax)
    res.skipped.push_back(std::string("z-max pyramid: ") +
                          (any_zmax ? "the chosen configuration does not classify ESM failures"
                                    : "no candidate classifies ESM failures (esm not among the methods)"));
  if (res.found && res.chosen.lookup.kind == Lookup::Bilinear && target.lookup.kind != Lookup::Bilinear)
    res.skipped.push_back(std::string(target.lookup.kind == Lookup::Mips ? "mip pyramid" : "summed-area table") +
                          ": bilinear already meets the bound at the scene's footprints");
  if (res.found && res.chosen.method == "csm") {
    for (const auto& row : res.tried)
      if (row.method == "csm" && row.options.csm.order < res.chosen.csm.order &&
          metric_value(row.sref, req.metric) > req.max_error) {
        res.notes.push_back("csm: smaller orders miss the bound (" + row.label + ": " + req.metric + " " +
                            fmt(metric_value(row.sref, req.metric)) + ")");
        break;
      }
  }
  if (!res.not_tried.empty()) {
    std::map<std::string, int> by_method;
    for (const auto& c : res.not_tried) ++by_method[c.options.method];
    std::string list;
    for (const auto& [m, n] : by_method) list += (list.empty() ? "" : ", ") + m + " (" + std::to_string(n) + ")";
    res.skipped.push_back(std::to_string(res.not_tried.size()) + " configurations estimated at more than " +
                          fmt(req.cost_slack) + "x the first one under the bound (" + res.first_hit +
                          "): " + list);
  }
  return res;
}

std::string describe(const AutoResult& r, const std::string& metric) {
  std::ostringstream s;
  for (const auto& n : r.notes) s << "auto: " << n << "\n";
  if (!r.found) {
    s << "auto: no configuration meets the bound";
    const Row* best = nullptr;
    for (const auto& row : r.tried)
      if (!best || metric_value(row.sref, metric) < metric_value(best->sref, metric)) best = &row;
    if (best)
      s << "; closest: " << best->label << " (" << metric << " " << fmt(metric_value(best->sref, metric)) << ", "
        << fmt(best->time_ms) << " ms)";
    s << "\n";
  } else {
    const Row& c = r.chosen_row;
    s << "auto: chose " << c.label << ": " << fmt(c.min_ms) << " ms (fastest of " << c.runs << " runs; median of the first pass "
      << fmt(c.time_ms) << "), " << metric << " " << fmt(metric_value(c.sref, metric)) << " (p99 " << fmt(c.sref.p99)
      << ", rmse " << fmt(c.sref.rmse) << ", max " << fmt(c.sref.max) << "), " << fmt(c.device_bytes / 1048576.0, 3)
      << " MiB\n";
    s << "auto: why: " << r.first_hit << " was the first configuration under the bound in estimated-cost order; "
      << "of the " << r.tried.size() << " tried up to the cost slack, the " << r.finalists.size()
      << " under the bound ran again in interleaved rounds and this one was the fastest"
      << (r.tie.empty() ? "" : " within noise (" + r.tie + ")") << "\n";
    std::string list;
    for (const auto& f : r.finalists)
      list += (list.empty() ? "" : ", ") + f.label + " x" + fmt(f.score, 3) + " (" + fmt(f.min_ms) + " ms)";
    s << "auto: finalists (median time over the round's fastest; fastest run): " << list << "; measured noise "
      << fmt(100.0 * r.noise, 2) << "%, tie band " << fmt(100.0 * r.tolerance, 2) << "%\n";
  }
  for (const auto& k : r.skipped) s << "auto: skipped " << k << "\n";
  for (size_t i = 0; i < r.tried.size(); ++i) {
    const Row& row = r.tried[i];
    s << "auto:   tried " << row.label << ": " << fmt(row.time_ms) << " ms (estimate " << fmt(r.tried_cost[i], 3)
      << "), " << metric << " " << fmt(metric_value(row.sref, metric)) << "\n";
  }
  // Refusals grouped by reason.
  std::map<std::string, std::string> by_reason;
  for (const auto& k : r.refused) {
    auto& list = by_reason[k.reason];
    list += (list.empty() ? "" : ", ") + k.label;
  }
  for (const auto& [reason, list] : by_reason) s << "auto: refused (" << reason << "): " << list << "\n";
  return s.str();
}

}  // namespace sf::eval

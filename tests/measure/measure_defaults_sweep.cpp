// The defaults sweep (docs/results.md "Defaults sweep", scripts/defaults_sweep.sh):
// every method of the registry and every soft method over a table of candidate parameter settings
// on every scene; per scene x method x candidate, acne and leak against reference_hard and RMSE
// against the ray-traced references, over the receivers facing the light (eval::Scene::traced).
// Not part of the test suite (sf_measure).
//   SF_SWEEP_SCENES="dir ..." SF_SWEEP_OUT=rows.csv [SF_SWEEP_RADIUS=2] [SF_SWEEP_METHODS="esm pcss"]
//   [SF_SWEEP_NORMAL_OFFSETS="0 0.5 1"] sf_measure --gtest_filter='DefaultsSweep.Run'
// Every candidate runs at every normal offset of SF_SWEEP_NORMAL_OFFSETS (texels, default "0
// 0.5"), labelled "noff=T ..."; the receivers need nx ny nz.
// Scene dirs are the scene tool's (shadowmap.exr with the light in its header, receivers.exr with
// ndl, both references). Basis methods run with --blur-radius SF_SWEEP_RADIUS where the method
// follows the prefilter, soft methods with the scene's light. The selection rule and the tables:
// measure_defaults_tables.cpp (DefaultsSweep.Tables).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "evaluate.hpp"
#include "scene_light.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/normal_offset.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/soft.hpp"
#include "sweep_rows.hpp"

namespace sf::test {
namespace {

// ---- the candidate table ------------------------------------------------------------------------

// A candidate setting: its label and what it sets on top of the method's defaults.
template <class Options>
struct Choice {
  std::string label;
  std::function<void(Options&)> set;
};
using Setting = Choice<FilterOptions>;
using SoftSetting = Choice<SoftOptions>;

// 2^-15 is the tie bias of sm and pcf with the receiver plane (docs/receiver_plane.md).
constexpr double kTieBias = 1.0 / 32768.0;

std::string value_label(double v) {
  if (v == kTieBias) return "2^-15";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// One setting per value: "key=value".
template <class Options>
std::vector<Choice<Options>> axis(const std::string& key, const std::vector<double>& values,
                                  std::function<void(Options&, double)> set) {
  std::vector<Choice<Options>> out;
  for (double v : values) out.push_back({key + "=" + value_label(v), [set, v](Options& o) { set(o, v); }});
  return out;
}

// Every pair of settings of a and b, labels joined by a space.
template <class Options>
std::vector<Choice<Options>> cross(const std::vector<Choice<Options>>& a, const std::vector<Choice<Options>>& b) {
  std::vector<Choice<Options>> out;
  for (const auto& x : a)
    for (const auto& y : b)
      out.push_back({x.label.empty()   ? y.label
                     : y.label.empty() ? x.label
                                       : x.label + " " + y.label,
                     [sx = x.set, sy = y.set](Options& o) {
                       sx(o);
                       sy(o);
                     }});
  return out;
}

const std::vector<Setting> kAsIs = {{"", [](FilterOptions&) {}}};

// A filter method's candidates are its pipeline settings crossed with its reconstruction
// settings. A pipeline setting may change anything (basis transform, prefilter, classification)
// and gets a Pipeline of its own; a reconstruction setting may only change what the
// reconstruction kernel reads (biases, variances, offsets, scales), so every candidate of one
// pipeline setting reconstructs from the basis that setting prefiltered once.
// DefaultsSweep.SharedBasisIsExact checks that rule against filter().
struct FilterSweep {
  std::vector<Setting> pipeline, reconstruct;
};

FilterSweep filter_sweep(const std::string& method) {
  using O = FilterOptions;
  // The depth tests: against the receiver's plane with a small constant and its slope-scaled
  // bias, or against d with a constant bias alone.
  const std::vector<Setting> plane = cross(
      cross(std::vector<Setting>{{"plane", [](O& o) { o.receiver_plane.enabled = true; }}},
            axis<O>("bias", {kTieBias, 1e-4, 3e-4, 1e-3, 3e-3}, [](O& o, double v) { o.depth_test.bias = float(v); })),
      axis<O>("slope", {0, 0.25, 0.5, 1}, [](O& o, double v) { o.receiver_plane.slope_bias = float(v); }));
  const std::vector<Setting> no_plane =
      cross(std::vector<Setting>{{"no-plane", [](O& o) { o.receiver_plane.enabled = false; }}},
            axis<O>("bias", {0, kTieBias, 1e-4, 3e-4, 1e-3, 3e-3, 5e-3, 1e-2},
                    [](O& o, double v) { o.depth_test.bias = float(v); }));
  std::vector<Setting> depth_tests = plane;
  depth_tests.insert(depth_tests.end(), no_plane.begin(), no_plane.end());
  const std::vector<Setting> classify = {{"", [](O& o) { o.esm_classify.mode = EsmClassify::None; }},
                                         {"zmax", [](O& o) { o.esm_classify.mode = EsmClassify::ZMax; }},
                                         {"threshold", [](O& o) { o.esm_classify.mode = EsmClassify::Threshold; }}};
  const auto lbr = [](const std::vector<double>& a) {
    return axis<O>("lbr", a, [](O& o, double v) { o.vsm.lbr = float(v); });
  };
  const auto min_variance = [](const std::vector<double>& v) {
    return axis<O>("vmin", v, [](O& o, double x) { o.vsm.min_variance = float(x); });
  };
  const auto pos = axis<O>("c+", {5, 10, 20, 30, 40, 42}, [](O& o, double v) { o.evsm.pos = float(v); });
  const auto moments =
      cross(axis<O>("a", {3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3},
                    [](O& o, double v) { o.msm.moment_bias = float(v); }),
            axis<O>("bias", {0, 1e-4, 3e-4, 1e-3, 3e-3}, [](O& o, double v) { o.depth_test.bias = float(v); }));
  if (method == "sm" || method == "pcf") return {kAsIs, depth_tests};
  if (method == "esm")
    return {cross(axis<O>("c", {20, 40, 60, 80, 120, 160}, [](O& o, double v) { o.esm.c = float(v); }), classify),
            kAsIs};
  if (method == "vsm")
    return {kAsIs, cross(min_variance({1e-7, 1e-6, 1e-5, 2e-5, 1e-4, 1e-3}), lbr({0, 0.1, 0.2, 0.3, 0.5}))};
  const auto evsm_vmin = min_variance({1e-5, 1e-4, 1e-3, 1e-2});
  if (method == "evsm2") return {pos, cross(evsm_vmin, lbr({0, 0.2}))};
  if (method == "evsm4")
    return {cross(pos, axis<O>("c-", {5, 10, 20, 42}, [](O& o, double v) { o.evsm.neg = float(v); })),
            cross(evsm_vmin, lbr({0, 0.2}))};
  if (method == "msm" || method == "msm-hausdorff") return {kAsIs, moments};
  if (method == "csm") {
    // The order stays at its default; offset and scale on a grid around the order's measured
    // defaults (csm_parameters), with and without ringing attenuation.
    FilterOptions o;
    o.method = "csm";
    const CsmParameters d = csm_parameters(o);
    const double s = d.scale;
    return {kAsIs, cross(cross(axis<O>("offset", {0, 0.5 * d.offset, d.offset, 1.5 * d.offset, 2.5 * d.offset},
                                       [](O& o, double v) { o.csm.offset = float(v); }),
                               axis<O>("scale", {s * 5 / 7, s * 6 / 7, s, s * 8 / 7, s * 10 / 7, s * 12 / 7, s * 2},
                                       [](O& o, double v) { o.csm.scale = float(v); })),
                         axis<O>("alpha", {0, 1}, [](O& o, double v) { o.csm.alpha = float(v); }))};
  }
  return {kAsIs, kAsIs};  // a method the table does not know yet: its defaults only
}

std::vector<SoftSetting> soft_sweep(SoftMethod m) {
  using O = SoftOptions;
  if (m == SoftMethod::Cssm) {
    SoftOptions o;
    o.method = m;
    const CssmParams d = cssm_params(o);
    // Offsets from the default to 3x it: smaller ones keep a lit receiver lit only at large
    // scales, larger ones leak (docs/results.md "Defaults sweep"). Settings that validate()
    // refuses (a lit receiver would reconstruct below 1, which the sharpening darkens) are left
    // out by soft_candidates(). Each cssm candidate builds its own basis and SAT, the costliest
    // step of the sweep at 2048, so the grid is kept small.
    return cross(axis<O>("offset", {d.offset, 1.5 * d.offset, 2 * d.offset, 3 * d.offset},
                         [](O& o, double v) { o.cssm.offset = float(v); }),
                 axis<O>("scale", {1.25, 1.5, 2, 3, 4}, [](O& o, double v) { o.cssm.scale = float(v); }));
  }
  // pcss, ssmm: against the receiver's plane with a constant and the slope-scaled bias, or
  // against d with a constant bias alone.
  std::vector<SoftSetting> out = cross(
      cross(std::vector<SoftSetting>{{"plane", [](O& o) { o.receiver_plane.enabled = true; }}},
            axis<O>("bias", {kTieBias, 1e-4, 5e-4, 2e-3, 5e-3, 1e-2, 2e-2}, [](O& o, double v) { o.bias = float(v); })),
      axis<O>("slope", {0, 0.25, 0.5, 1}, [](O& o, double v) { o.receiver_plane.slope_bias = float(v); }));
  const std::vector<SoftSetting> no_plane =
      cross(std::vector<SoftSetting>{{"no-plane", [](O& o) { o.receiver_plane.enabled = false; }}},
            axis<O>("bias", {0, 1e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 3e-2, 5e-2},
                    [](O& o, double v) { o.bias = float(v); }));
  out.insert(out.end(), no_plane.begin(), no_plane.end());
  return out;
}

// ---- what a candidate is ------------------------------------------------------------------------

// Every parameter in effect (defaults resolved): equal strings are equal settings. The default
// candidate is the one whose fingerprint equals that of default-constructed options.
std::string fingerprint(const FilterOptions& o) {
  std::ostringstream s;
  s.precision(9);
  for (const MethodParameter& p : o.method->parameter_values(o)) s << p.key << '=' << p.value << ' ';
  s << "bias=" << depth_bias(o) << " plane=" << o.receiver_plane.enabled << ',' << o.receiver_plane.max_slope << ','
    << o.receiver_plane.slope_bias << " classify=" << int(classify_mode(o)) << ',' << o.esm_classify.zmax_offset << ','
    << o.esm_classify.threshold_eps << " storage=" << int(o.storage) << " blur=" << o.blur.radius << ',' << o.blur.sigma
    << " lookup=" << int(o.lookup.kind) << " noff=" << normal_offset(o);
  return s.str();
}

std::string fingerprint(const SoftOptions& o) {
  std::ostringstream s;
  s.precision(9);
  const CssmParams c = cssm_params(o);
  s << soft_method_name(o.method) << " bias=" << o.bias << " plane=" << o.receiver_plane.enabled << ','
    << o.receiver_plane.max_slope << ',' << o.receiver_plane.slope_bias << " max_width=" << o.max_width
    << " ssmm_n=" << o.ssmm.n << " cssm=" << o.cssm.order << ',' << int(o.cssm.lookup) << ',' << c.offset << ','
    << c.z_offset << ',' << c.scale << ',' << c.width_scale << ',' << c.sharpen_a << ',' << c.sharpen_b << ','
    << o.cssm.normalise << ',' << o.cssm.min_den << ',' << o.cssm.contact << " noff=" << soft_normal_offset(o);
  return s.str();
}

struct FilterCandidate {
  std::string label;
  FilterOptions options;
  size_t group = 0;  // index of its pipeline setting: candidates of one group share the basis
  bool is_default = false;
};

struct SoftCandidate {
  std::string label;
  SoftOptions options;  // the light is the scene's
  bool is_default = false;
};

int blur_radius() {
  const char* r = std::getenv("SF_SWEEP_RADIUS");
  return r ? std::atoi(r) : 2;
}

// The normal offsets of SF_SWEEP_NORMAL_OFFSETS, else 0 and 0.5 (every method's default is one
// of them): the receivers are uploaded moved once per offset, so every candidate states its own.
std::vector<double> normal_offsets() {
  std::vector<double> v;
  const char* e = std::getenv("SF_SWEEP_NORMAL_OFFSETS");
  std::istringstream in(e ? e : "");
  for (double t; in >> t;) v.push_back(t);
  if (v.empty()) v = {0.0, 0.5};
  return v;
}

// A candidate at normal offset `t` (labelled when the sweep lists offsets).
template <class Options>
void at_normal_offset(std::string& label, Options& o, std::optional<double> t) {
  if (!t) return;
  o.normal_offset = float(*t);
  label = "noff=" + value_label(*t) + (label == "defaults" ? "" : " " + label);
}

// Names from SF_SWEEP_METHODS (empty: every method).
bool wanted(const std::string& name) {
  const char* e = std::getenv("SF_SWEEP_METHODS");
  if (!e || !*e) return true;
  std::istringstream in(e);
  for (std::string s; in >> s;)
    if (s == name) return true;
  return false;
}

// The candidates of a registry method; when no setting of the table equals the defaults, the
// defaults are added as a candidate of their own, so that every table has the default's row.
std::vector<FilterCandidate> filter_candidates(const MethodDesc& m, int radius, std::optional<double> offset) {
  FilterOptions base;
  base.method = m.name;
  if (m.filtered) base.blur.radius = radius;
  const std::string def = fingerprint(base);
  if (offset) base.normal_offset = float(*offset);
  const FilterSweep sw = filter_sweep(m.name);
  std::vector<FilterCandidate> out;
  bool have_default = false;
  for (size_t g = 0; g < sw.pipeline.size(); ++g)
    for (const Setting& r : sw.reconstruct) {
      FilterCandidate c;
      c.options = base;
      sw.pipeline[g].set(c.options);
      r.set(c.options);
      const std::string& p = sw.pipeline[g].label;
      c.label = p.empty() ? r.label : r.label.empty() ? p : p + " " + r.label;
      if (c.label.empty()) c.label = "defaults";
      at_normal_offset(c.label, c.options, offset);
      c.group = g;
      c.is_default = fingerprint(c.options) == def;
      have_default = have_default || c.is_default;
      out.push_back(c);
    }
  if (!have_default && fingerprint(base) == def) out.push_back({"defaults", base, sw.pipeline.size(), true});
  return out;
}

std::vector<SoftCandidate> soft_candidates(SoftMethod m, std::optional<double> offset) {
  SoftOptions base;
  base.method = m;
  const std::string def = fingerprint(base);
  if (offset) base.normal_offset = float(*offset);
  std::vector<SoftCandidate> out;
  bool have_default = false;
  std::string refused;
  for (const SoftSetting& s : soft_sweep(m)) {
    SoftCandidate c{s.label, base, false};
    s.set(c.options);
    at_normal_offset(c.label, c.options, offset);
    try {
      validate(c.options);  // with the default light: these checks do not depend on the scene's
    } catch (const InputError&) {
      refused += " [" + s.label + "]";
      continue;
    }
    c.is_default = fingerprint(c.options) == def;
    have_default = have_default || c.is_default;
    out.push_back(c);
  }
  if (!have_default && fingerprint(base) == def) out.push_back({"defaults", base, true});
  if (!refused.empty()) std::fprintf(stderr, "sweep: %s refuses%s\n", soft_method_name(m), refused.c_str());
  return out;
}

constexpr SoftMethod kSoftMethods[] = {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved};

// ---- one scene on the device --------------------------------------------------------------------

std::vector<std::string> scene_dirs() {
  std::vector<std::string> v;
  const char* e = std::getenv("SF_SWEEP_SCENES");
  std::istringstream in(e ? e : "");
  for (std::string s; in >> s;) v.push_back(s);
  return v;
}

// The scene loaded once, its depth map and receivers uploaded once for every candidate.
struct DeviceScene {
  eval::Scene scene;
  std::string label;  // name and map size: "spheres-512"
  SoftLight light;
  cl::Buffer depth, u, v, d, f;
  DeviceReceivers rx;
  cl::Buffer visibility;

  // The receivers uploaded are moved `offset` texels along their normals (none when unset).
  DeviceScene(const std::string& dir, std::optional<double> offset) : scene(eval::load_scene(dir)) {
    if (offset && !scene.receivers.has_normal)
      throw std::runtime_error(dir + ": receivers without nx ny nz (regenerate the scene)");
    const Receivers r =
        offset ? offset_along_normals(scene.receivers, scene.depth.width, scene.depth.height, float(*offset))
               : scene.receivers;
    if (!r.has_ndl) throw std::runtime_error(dir + ": receivers without ndl (regenerate the scene)");
    if (r.grid || scene.ref_hard.texels() != r.count() || scene.ref_soft.texels() != r.count())
      throw std::runtime_error(dir + ": camera receivers and both references needed");
    label = scene.name + "-" + std::to_string(scene.depth.width);
    light = header_light(dir + "/shadowmap.exr");
    depth = to_device(scene.depth.data);
    u = to_device(r.u);
    v = to_device(r.v);
    d = to_device(r.d);
    if (r.has_footprint) f = to_device(r.f);
    rx.count = r.count();
    rx.row = r.width;
    rx.u = u, rx.v = v, rx.d = d;  // rx.f stays empty: the sweep's lookups are bilinear
    visibility = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, rx.count * sizeof(float));
  }
  std::vector<float> read(const cl::Event& done) const {
    std::vector<float> out(rx.count);
    const EventList after{done};
    runtime().queue().enqueueReadBuffer(visibility, CL_TRUE, 0, out.size() * sizeof(float), out.data(), &after);
    return out;
  }
};

double rmse(const std::vector<float>& v, const HostImage& ref, const std::vector<uint8_t>& mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < v.size(); ++i)
    if (mask[i]) {
      const double e = double(v[i]) - ref.data[i];
      sum += e * e;
      ++n;
    }
  return n ? std::sqrt(sum / n) : 0.0;
}

sweep::Row measure_row(const DeviceScene& ds, const std::string& method, const std::string& label, bool is_default,
                       const std::vector<float>& v) {
  const eval::Scene& s = ds.scene;
  const eval::AcneLeak al = eval::acne_leak(v, s.ref_hard, s.traced);
  sweep::Row r;
  r.scene = ds.label;
  r.method = method;
  r.candidate = label;
  r.is_default = is_default;
  r.acne = al.acne;
  r.leak = al.leak;
  r.lit = al.lit;
  r.shadowed = al.shadowed;
  r.soft_rmse = rmse(v, s.ref_soft, s.traced);
  r.hard_rmse = rmse(v, s.ref_hard, s.traced);
  return r;
}

// Visibility of every candidate of one group: one Pipeline with the first candidate's options
// prefilters once; the first reconstructs through it, the others read its basis with their own
// reconstruction options (the candidate table's rule).
void run_group(const DeviceScene& ds, const MethodDesc& m, const std::vector<FilterCandidate>& group,
               const std::function<void(const FilterCandidate&, const std::vector<float>&)>& take) {
  const FilterOptions& first = group.front().options;
  if (classify_mode(first) != EsmClassify::None && group.size() > 1)
    throw std::logic_error("a classifying pipeline setting cannot share its basis (the stage runs in reconstruct())");
  if (first.lookup.kind != Lookup::Bilinear) throw std::logic_error("the sweep shares bilinear bases only");
  const int w = ds.scene.depth.width, h = ds.scene.depth.height;
  Pipeline pipe(runtime_ptr(), first, w, h);
  const cl::Event pre = pipe.prefilter(ds.depth);
  const EventList after{pre};
  take(group.front(), ds.read(pipe.reconstruct(ds.rx, ds.visibility, &after)));
  const LookupBuffers lookup = pipe.lookup_tables();
  for (size_t k = 1; k < group.size(); ++k) {
    const cl::Event done = enqueue_reconstruct_points(runtime(), m, group[k].options, w, h, ds.rx.count, ds.rx.row,
                                                      pipe.basis(), &lookup, ds.u, ds.v, ds.d, ds.visibility, &after);
    take(group[k], ds.read(done));
  }
}

std::vector<float> run_soft(const DeviceScene& ds, SoftOptions o) {
  o.light = ds.light;
  SoftFilter filter(runtime_ptr(), o, ds.scene.depth.width, ds.scene.depth.height);
  const EventList after{filter.prefilter(ds.depth)};
  // The receiver image's rows give each receiver's plane, as soft_filter() passes them.
  DeviceReceivers rx = ds.rx;
  rx.f = ds.f;
  return ds.read(filter.reconstruct(rx, ds.visibility, &after));
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Every wanted method with its candidates, built once for every scene.
struct Plan {
  struct Filter {
    const MethodDesc* method;
    std::vector<std::vector<FilterCandidate>> groups;  // by pipeline setting
  };
  struct Soft {
    SoftMethod method;
    std::vector<SoftCandidate> candidates;
  };
  std::vector<Filter> filters;
  std::vector<Soft> softs;
};

Plan make_plan(int radius, std::optional<double> offset) {
  Plan p;
  for (const MethodDesc& m : methods()) {
    if (!wanted(m.name)) continue;
    Plan::Filter f{&m, {}};
    for (const FilterCandidate& c : filter_candidates(m, radius, offset)) {
      if (c.group >= f.groups.size()) f.groups.resize(c.group + 1);
      f.groups[c.group].push_back(c);
    }
    p.filters.push_back(f);
  }
  for (SoftMethod sm : kSoftMethods)
    if (wanted(soft_method_name(sm))) p.softs.push_back({sm, soft_candidates(sm, offset)});
  return p;
}

// Every candidate of the plan on one scene; returns the seconds per method ("sm 0.1 pcf 0.2 ...").
std::string sweep_scene(const DeviceScene& ds, const Plan& plan, std::vector<sweep::Row>& rows) {
  std::string times;
  auto took = [&](const std::string& name, std::chrono::steady_clock::time_point t0) {
    char b[64];
    std::snprintf(b, sizeof b, "%s%s %.1f", times.empty() ? "" : " ", name.c_str(), seconds_since(t0));
    times += b;
  };
  for (const Plan::Filter& f : plan.filters) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& g : f.groups) {
      if (g.empty()) continue;
      try {
        run_group(ds, *f.method, g, [&](const FilterCandidate& c, const std::vector<float>& v) {
          rows.push_back(measure_row(ds, f.method->name, c.label, c.is_default, v));
        });
      } catch (const InputError& e) {  // a setting the method refuses: no row, said once
        std::fprintf(stderr, "%s %s %s: refused: %s\n", ds.label.c_str(), f.method->name.c_str(),
                     g.front().label.c_str(), e.what());
      }
    }
    took(f.method->name, t0);
  }
  for (const Plan::Soft& sp : plan.softs) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const SoftCandidate& c : sp.candidates) {
      const char* name = soft_method_name(sp.method);
      try {
        rows.push_back(measure_row(ds, name, c.label, c.is_default, run_soft(ds, c.options)));
      } catch (const InputError& e) {
        std::fprintf(stderr, "%s %s %s: refused: %s\n", ds.label.c_str(), name, c.label.c_str(), e.what());
      }
    }
    took(soft_method_name(sp.method), t0);
  }
  return times;
}

TEST(DefaultsSweep, Run) {
  const std::vector<std::string> dirs = scene_dirs();
  ASSERT_FALSE(dirs.empty()) << "set SF_SWEEP_SCENES";
  const char* out = std::getenv("SF_SWEEP_OUT");
  const std::string path = out && *out ? out : "defaults_sweep.csv";
  std::vector<std::optional<double>> offsets;
  for (double t : normal_offsets()) offsets.push_back(t);
  std::vector<Plan> plans;
  for (const auto& t : offsets) plans.push_back(make_plan(blur_radius(), t));
  std::vector<sweep::Row> rows;
  for (const std::string& dir : dirs)
    for (size_t k = 0; k < offsets.size(); ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const size_t before = rows.size();
      const DeviceScene ds(dir, offsets[k]);
      const std::string times = sweep_scene(ds, plans[k], rows);
      std::fprintf(stderr, "sweep: %s: %zu rows in %.1f s (%s)\n", ds.label.c_str(), rows.size() - before,
                   seconds_since(t0), times.c_str());
    }
  sweep::write_csv(path, rows);
  std::fprintf(stderr, "sweep: %zu rows -> %s\n", rows.size(), path.c_str());
}

// The sharing rule of the candidate table, checked: on the first scene every candidate's
// visibility through the shared basis equals filter() with its own options, bit for bit.
TEST(DefaultsSweep, SharedBasisIsExact) {
  const std::vector<std::string> dirs = scene_dirs();
  ASSERT_FALSE(dirs.empty()) << "set SF_SWEEP_SCENES";
  const std::optional<double> offset = normal_offsets().back();
  const DeviceScene ds(dirs.front(), offset);
  size_t checked = 0;
  for (const Plan::Filter& f : make_plan(blur_radius(), offset).filters)
    for (const auto& g : f.groups) {
      if (g.empty()) continue;
      run_group(ds, *f.method, g, [&](const FilterCandidate& c, const std::vector<float>& shared) {
        const auto own = filter(runtime_ptr(), c.options, ds.scene.depth, ds.scene.receivers).visibility.data;
        // filter() also sets the receivers facing away to 0 (no row counts them).
        std::vector<float> v = shared;
        shadow_facing_away(ds.scene.receivers, v);
        size_t differ = 0;
        for (size_t i = 0; i < v.size(); ++i) differ += !(v[i] == own[i] || (std::isnan(v[i]) && std::isnan(own[i])));
        EXPECT_EQ(differ, 0u) << f.method->name << " " << c.label;
        ++checked;
      });
    }
  std::fprintf(stderr, "sweep: %zu candidates checked against filter() on %s\n", checked, ds.label.c_str());
}

}  // namespace
}  // namespace sf::test

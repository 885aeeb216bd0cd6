// evaluate's outputs: results.csv, results.json, the Pareto plots and error images.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "drawing.hpp"
#include "eval_util.hpp"
#include "evaluate.hpp"
#include "image_io.hpp"
#include "output_file.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {
namespace {

using detail::lookup_name;

// A results file is composed in memory and written whole by the one writer (output_file.hpp).
std::ostringstream text_out() {
  std::ostringstream f;
  f.precision(6);
  return f;
}

std::string csv_quote(const std::string& s) { return "\"" + s + "\""; }

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o;
}

double num(double v) { return std::isfinite(v) ? v : -1.0; }

void stats_json(std::ostream& f, const char* name, const ErrorStats& e) {
  f << "\"" << name << "\": ";
  if (!e.valid) {
    f << "null";
    return;
  }
  f << "{\"n\": " << e.n << ", \"rmse\": " << num(e.rmse) << ", \"p99\": " << num(e.p99) << ", \"max\": " << num(e.max)
    << ", \"frac_1_255\": " << e.frac_1_255 << ", \"frac_005\": " << e.frac_005 << ", \"leak\": " << e.leak
    << ", \"darken\": " << e.darken << "}";
}

// A row's filter as the files list it: blur radius, lookup, storage and the parameters in effect.
// A soft row has no blur; cssm reads its basis through its lookup in its storage, pcss and ssmm
// the raw depth ("raw", f32); its parameters: cssm's order M, ssmm's n, and the light's sides.
struct RowFilter {
  int radius = 0;
  std::string lookup, storage;
  std::vector<std::pair<std::string, double>> parameters;
};
RowFilter row_filter(const Row& r) {
  RowFilter f;
  if (r.soft_options) {
    const SoftOptions& o = *r.soft_options;
    const bool cssm = o.method == SoftMethod::Cssm;
    f.lookup = cssm ? lookup_name(o.cssm.lookup) : "raw";
    f.storage = storage_name(cssm ? o.cssm.storage : Storage::F32);
    if (cssm) f.parameters.emplace_back("order", o.cssm.order);
    if (o.method == SoftMethod::Ssmm || o.method == SoftMethod::SsmmImproved) f.parameters.emplace_back("n", o.ssmm.n);
    f.parameters.emplace_back("light_size", o.light.size);
    f.parameters.emplace_back("light_height", light_height(o.light));
    return f;
  }
  const FilterOptions& o = r.options;
  f.radius = o.blur.radius;
  f.lookup = lookup_name(o.lookup.kind);
  f.storage = storage_name(o.storage);
  for (const MethodParameter& p : o.method->parameter_values(o)) f.parameters.emplace_back(p.key, p.value);
  return f;
}

}  // namespace

// The parameters in effect, "key=value" separated by spaces (the registry's names; a soft row's,
// row_filter).
std::string parameter_text(const Row& r) {
  std::string s;
  for (const auto& [key, value] : row_filter(r).parameters) {
    std::ostringstream v;
    v << value;
    s += (s.empty() ? "" : " ") + key + "=" + v.str();
  }
  return s;
}

// Error columns: "self" (s_ref of the configuration's own weights; the files before the target
// column called it "sref"), hard and soft (ray-traced), then after every older column the target
// (s_ref of the run's target filter, named in target_filter).
void write_csv(const std::string& path, const std::vector<Row>& rows, const TargetFilter& target) {
  std::ostringstream f = text_out();
  f << "scene,method,config,blur_radius,lookup,storage,parameters,time_ms,min_ms,runs,"
       "transform_ms,blur_ms,mips_ms,sat_ms,zmax_ms,reconstruct_ms,classify_ms,device_bytes";
  static const char* metrics[] = {"rmse", "p99", "max", "frac_1_255", "frac_005", "leak", "darken"};
  for (const char* ref : {"self", "hard", "soft"})
    for (const char* m : metrics) f << "," << ref << "_" << m;
  // Acne and umbra leaks against reference_hard (eval::acne_leak), after every older column.
  f << ",acne,umbra_leak,lit_inside,shadowed_inside";
  f << ",target_filter";
  for (const char* m : metrics) f << ",target_" << m;
  f << "\n";
  auto stats = [&f](const ErrorStats& e) {
    if (!e.valid) {
      f << ",,,,,,,";
      return;
    }
    f << "," << e.rmse << "," << e.p99 << "," << e.max << "," << e.frac_1_255 << "," << e.frac_005 << "," << e.leak
      << "," << e.darken;
  };
  for (const auto& r : rows) {
    const RowFilter o = row_filter(r);
    f << r.scene << "," << r.method << "," << csv_quote(r.label) << "," << o.radius << "," << o.lookup << ","
      << o.storage << "," << csv_quote(parameter_text(r)) << "," << r.time_ms << "," << r.min_ms << "," << r.runs << ","
      << r.stages.transform * 1e3 << "," << r.stages.blur * 1e3 << "," << r.stages.pyramid * 1e3 << ","
      << r.stages.sat * 1e3 << "," << r.stages.zmax * 1e3 << "," << r.stages.reconstruct * 1e3 << ","
      << r.stages.classify * 1e3 << "," << r.device_bytes;
    for (const ErrorStats* e : {&r.sref, &r.hard, &r.soft}) stats(*e);
    const AcneLeak& al = r.acne_leak;
    if (al.valid)
      f << "," << al.acne << "," << al.leak << "," << al.lit << "," << al.shadowed;
    else
      f << ",,,,";
    f << "," << csv_quote(r.target.valid ? target_text(target) : "");
    stats(r.target);
    f << "\n";
  }
  io::write_text(path, "results file", f.str());
}

void write_json(const std::string& path, const std::vector<Row>& rows, const std::vector<Skipped>& skipped,
                const std::string& device, const TargetFilter& target) {
  std::ostringstream f = text_out();
  f << "{\n  \"device\": \"" << json_escape(device) << "\",\n"
    << "  \"time\": \"median wall ms of prefilter + reconstruct + finish with the inputs on the device, "
       "after warm-up; stage times are device profiling medians\",\n"
    << "  \"errors\": \"self: against s_ref with the configuration's own weights (fidelity to its own filter; "
       "sm and pcf are 0 by definition); target: against s_ref of target_filter, the same for every "
       "configuration; hard/soft: against the ray-traced camera-view references over the receivers that face "
       "the light (ndl > 0); receivers with finite depth inside the light frustum only; acne / umbra_leak: "
       "receivers lit / shadowed in reference_hard at every counted receiver of their 7x7 window that come out "
       "below / above 0.5, as fractions of lit_inside / shadowed_inside\",\n"
    << "  \"target_filter\": {\"blur_radius\": " << target.blur.radius << ", \"lookup\": \""
    << lookup_name(target.lookup) << "\"},\n"
    << "  \"results\": [\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const RowFilter o = row_filter(r);
    f << "    {\"scene\": \"" << json_escape(r.scene) << "\", \"method\": \"" << r.method << "\", \"config\": \""
      << json_escape(r.label) << "\", \"soft\": " << (r.soft_options ? "true" : "false")
      << ", \"parameters\": {\"blur_radius\": " << o.radius << ", \"lookup\": \"" << o.lookup << "\", \"storage\": \""
      << o.storage << "\"";
    for (const auto& [key, value] : o.parameters) f << ", \"" << json_escape(key) << "\": " << value;
    f << "}, \"time_ms\": " << r.time_ms << ", \"min_ms\": " << r.min_ms << ", \"runs\": " << r.runs
      << ", \"stages_ms\": {\"transform\": " << r.stages.transform * 1e3 << ", \"blur\": " << r.stages.blur * 1e3
      << ", \"mips\": " << r.stages.pyramid * 1e3 << ", \"sat\": " << r.stages.sat * 1e3
      << ", \"zmax\": " << r.stages.zmax * 1e3 << ", \"reconstruct\": " << r.stages.reconstruct * 1e3
      << ", \"classify\": " << r.stages.classify * 1e3 << "}, \"device_bytes\": " << r.device_bytes << ", ";
    stats_json(f, "self", r.sref);
    f << ", ";
    stats_json(f, "target", r.target);
    f << ", ";
    stats_json(f, "hard", r.hard);
    f << ", ";
    stats_json(f, "soft", r.soft);
    f << ", \"acne_leak\": ";
    if (r.acne_leak.valid)
      f << "{\"acne\": " << r.acne_leak.acne << ", \"umbra_leak\": " << r.acne_leak.leak
        << ", \"lit_inside\": " << r.acne_leak.lit << ", \"shadowed_inside\": " << r.acne_leak.shadowed << "}";
    else
      f << "null";
    f << "}" << (i + 1 < rows.size() ? "," : "") << "\n";
  }
  f << "  ],\n  \"skipped\": [\n";
  for (size_t i = 0; i < skipped.size(); ++i)
    f << "    {\"scene\": \"" << json_escape(skipped[i].scene) << "\", \"config\": \"" << json_escape(skipped[i].label)
      << "\", \"reason\": \"" << json_escape(skipped[i].reason) << "\"}" << (i + 1 < skipped.size() ? "," : "") << "\n";
  f << "  ]\n}\n";
  io::write_text(path, "results file", f.str());
}

void write_pareto_png(const std::string& path, const std::vector<Row>& rows, Reference ref, const std::string& metric,
                      const PlotLabels& labels) {
  namespace IBA = OIIO::ImageBufAlgo;
  using draw::text;
  const int W = 1200, H = 700, L = 80, R = 180, T = 90, B = 60;  // plot area margins (legend right)
  OIIO::ImageBuf img(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::FLOAT));
  IBA::fill(img, {1.0f, 1.0f, 1.0f});
  const std::vector<float> black{0, 0, 0}, grey{0.85f, 0.85f, 0.85f}, dim{0.35f, 0.35f, 0.35f};
  text(img, 12, 26, labels.title, black, 17);
  text(img, 12, 48, labels.subtitle, dim, 13);
  text(img, L, T - 12, "error: " + labels.y_axis, black, 13);
  text(img, std::max(L, (L + W - R) / 2 - draw::text_width(labels.x_axis, 14) / 2), H - 15, labels.x_axis, black, 14);
  std::vector<size_t> shown;  // rows measured against the reference
  for (size_t i = 0; i < rows.size(); ++i)
    if (std::isfinite(row_error(rows[i], ref, metric)) && std::isfinite(rows[i].time_ms)) shown.push_back(i);
  if (shown.empty()) {
    IBA::render_box(img, L, T, W - R, H - B, black);
    draw::write_png8(path, img, labels.description());
    return;
  }
  double tmin = INFINITY, tmax = 0, emax = 0;
  for (size_t i : shown) {
    tmin = std::min(tmin, rows[i].time_ms);
    tmax = std::max(tmax, rows[i].time_ms);
    emax = std::max(emax, row_error(rows[i], ref, metric));
  }
  tmin = std::max(tmin, 1e-3);
  const double lt0 = std::floor(std::log10(tmin) * 4) / 4,
               lt1 = std::ceil(std::log10(std::max(tmax, tmin * 1.01)) * 4) / 4;
  // Error axis from 0 in five steps of a round size (1 to 8 times a power of ten).
  double step = 0.2;
  if (emax > 0) {
    const double raw = emax * 1.04 / 5, decade = std::pow(10.0, std::floor(std::log10(raw)));
    step = 10 * decade;
    for (double m : {1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0})
      if (m * decade >= raw) {
        step = m * decade;
        break;
      }
  }
  emax = 5 * step;
  auto px = [&](double t) {
    return int(L + (std::log10(std::max(t, 1e-3)) - lt0) / std::max(lt1 - lt0, 1e-6) * (W - L - R));
  };
  auto py = [&](double e) { return int(H - B - std::min(e, emax) / emax * (H - T - B)); };
  // Grid: decades and 2x, 5x on time (finer when the axis spans about a decade or less), fifths
  // on error.
  const std::vector<double> marks =
      lt1 - lt0 > 1.25 ? std::vector<double>{1, 2, 5} : std::vector<double>{1, 1.5, 2, 3, 4, 5, 6, 8};
  for (int k = int(std::floor(lt0)); k <= int(std::ceil(lt1)); ++k)
    for (double m : marks) {
      const double t = m * std::pow(10.0, k), lt = std::log10(t);
      if (lt < lt0 - 1e-9 || lt > lt1 + 1e-9) continue;
      const int x = px(t);
      IBA::render_line(img, x, T, x, H - B, grey);
      std::ostringstream s;
      s << t;
      text(img, x - 8, H - B + 18, s.str(), black, 13);
    }
  for (int k = 0; k <= 5; ++k) {
    const double e = step * k;
    const int y = py(e);
    IBA::render_line(img, L, y, W - R, y, grey);
    std::ostringstream s;
    s.precision(3);
    s << e;
    text(img, 8, y + 5, s.str(), black, 13);
  }
  IBA::render_box(img, L, T, W - R, H - B, black);
  auto err = [&](size_t i) { return row_error(rows[i], ref, metric); };
  const auto front = pareto_front(rows, ref, metric);
  for (size_t k = 1; k < front.size(); ++k) {  // the front as a staircase
    const size_t a = front[k - 1], b = front[k];
    IBA::render_line(img, px(rows[a].time_ms), py(err(a)), px(rows[b].time_ms), py(err(a)), {0.2f, 0.2f, 0.2f});
    IBA::render_line(img, px(rows[b].time_ms), py(err(a)), px(rows[b].time_ms), py(err(b)), {0.2f, 0.2f, 0.2f});
  }
  for (size_t i : shown) {
    const int x = px(rows[i].time_ms), y = py(err(i));
    IBA::render_box(img, x - 3, y - 3, x + 3, y + 3, draw::method_colour(rows[i].method), true);
  }
  // Outline and label on the front points; a label that would cover an earlier one moves to the
  // next free line above or below its point.
  std::vector<OIIO::ROI> placed;
  for (size_t i : front) {
    const int x = px(rows[i].time_ms), y = py(err(i));
    IBA::render_box(img, x - 6, y - 6, x + 6, y + 6, black, false);
    const int w = draw::text_width(rows[i].label, 11);
    for (int dy : {-8, 16, -22, 30, -36, 44, -50}) {
      const OIIO::ROI box(x + 8, x + 8 + w, y + dy - 10, y + dy + 3);
      const bool free = std::none_of(placed.begin(), placed.end(), [&](const OIIO::ROI& p) {
        return box.xbegin < p.xend && p.xbegin < box.xend && box.ybegin < p.yend && p.ybegin < box.yend;
      });
      if (free || dy == -50) {
        text(img, box.xbegin, y + dy, rows[i].label, black, 11);
        placed.push_back(box);
        break;
      }
    }
  }
  std::vector<std::string> seen;  // legend
  for (size_t i : shown)
    if (std::find(seen.begin(), seen.end(), rows[i].method) == seen.end()) seen.push_back(rows[i].method);
  int ly = T + 10;
  for (const auto& m : seen) {
    IBA::render_box(img, W - R + 15, ly - 8, W - R + 25, ly + 2, draw::method_colour(m), true);
    text(img, W - R + 32, ly + 2, m, black, 14);
    ly += 22;
  }
  text(img, W - R + 15, ly + 10, "box = Pareto front", black, 12);
  draw::write_png8(path, img, labels.description());
}

void write_error_png(const std::string& path, const Scene& scene, const std::vector<float>& v,
                     const std::vector<double>& ref, double full_scale) {
  const Receivers& rx = scene.receivers;
  HostImage img(rx.width, rx.height, 3, 0.0f);
  for (size_t i = 0; i < rx.count() && i < v.size() && i < ref.size(); ++i) {
    if (!scene.valid[i]) {
      img.data[3 * i] = img.data[3 * i + 1] = img.data[3 * i + 2] = 0.2f;  // background: dark grey
      continue;
    }
    const double diff = double(v[i]) - ref[i];
    const float a = float(std::min(1.0, std::abs(diff) / full_scale));
    // Light leaks (v > s_ref) red, over-darkening blue, magnitude as brightness.
    img.data[3 * i] = diff > 0 ? a : 0.0f;
    img.data[3 * i + 1] = 0.0f;
    img.data[3 * i + 2] = diff < 0 ? a : 0.0f;
  }
  io::write_image(path, img);
}

}  // namespace sf::eval

// evaluate's outputs: results.csv, results.json, pareto_<scene>.png and error images.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "evaluate.hpp"
#include "image_io.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {
namespace {

std::ofstream open_out(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw InputError("cannot write '" + path + "'");
  f.precision(6);
  return f;
}

std::string csv_quote(const std::string& s) { return "\"" + s + "\""; }

const char* lookup_name(Lookup k) { return k == Lookup::Mips ? "mips" : k == Lookup::Sat ? "sat" : "bilinear"; }

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

std::vector<float> method_colour(const std::string& m) {
  const auto& c = find_method(m).colour;
  return {c[0], c[1], c[2]};
}

std::string font_path() {
  for (const char* p :
       {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"})
    if (std::filesystem::exists(p)) return p;
  return "";  // OIIO's default font search
}

void text(OIIO::ImageBuf& img, int x, int y, const std::string& s, const std::vector<float>& col, int size = 14) {
  // Text is a nicety: a machine without fonts still gets the points and the front.
  OIIO::ImageBufAlgo::render_text(img, x, y, s, size, font_path(), col);
}

}  // namespace

// The method's parameters in effect, "key=value" separated by spaces (the registry's names).
std::string parameter_text(const FilterOptions& o) {
  std::string s;
  for (const MethodParameter& p : find_method(o.method).parameter_values(o)) {
    std::ostringstream v;
    v << p.value;
    s += (s.empty() ? "" : " ") + p.key + "=" + v.str();
  }
  return s;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  auto f = open_out(path);
  f << "scene,method,config,blur_radius,lookup,storage,parameters,time_ms,min_ms,runs,"
       "transform_ms,blur_ms,mips_ms,sat_ms,zmax_ms,reconstruct_ms,classify_ms,device_bytes";
  for (const char* ref : {"sref", "hard", "soft"})
    for (const char* m : {"rmse", "p99", "max", "frac_1_255", "frac_005", "leak", "darken"})
      f << "," << ref << "_" << m;
  // Acne and umbra leaks against reference_hard (eval::acne_leak), after every older column.
  f << ",acne,umbra_leak,lit_inside,shadowed_inside";
  f << "\n";
  for (const auto& r : rows) {
    const auto& o = r.options;
    f << r.scene << "," << r.method << "," << csv_quote(r.label) << "," << o.blur.radius << ","
      << lookup_name(o.lookup.kind) << "," << storage_name(o.storage) << "," << csv_quote(parameter_text(o)) << ","
      << r.time_ms << "," << r.min_ms << "," << r.runs << "," << r.stages.transform * 1e3 << "," << r.stages.blur * 1e3
      << "," << r.stages.pyramid * 1e3 << "," << r.stages.sat * 1e3 << "," << r.stages.zmax * 1e3 << ","
      << r.stages.reconstruct * 1e3 << "," << r.stages.classify * 1e3 << "," << r.device_bytes;
    for (const ErrorStats* e : {&r.sref, &r.hard, &r.soft}) {
      if (!e->valid) {
        f << ",,,,,,,";
        continue;
      }
      f << "," << e->rmse << "," << e->p99 << "," << e->max << "," << e->frac_1_255 << "," << e->frac_005 << ","
        << e->leak << "," << e->darken;
    }
    const AcneLeak& al = r.acne_leak;
    if (al.valid)
      f << "," << al.acne << "," << al.leak << "," << al.lit << "," << al.shadowed;
    else
      f << ",,,,";
    f << "\n";
  }
  if (!f) throw InputError("cannot write '" + path + "'");
}

void write_json(const std::string& path, const std::vector<Row>& rows, const std::vector<Skipped>& skipped,
                const std::string& device) {
  auto f = open_out(path);
  f << "{\n  \"device\": \"" << json_escape(device) << "\",\n"
    << "  \"time\": \"median wall ms of prefilter + reconstruct + finish with the inputs on the device, "
       "after warm-up; stage times are device profiling medians\",\n"
    << "  \"errors\": \"sref: against s_ref with the configuration's own weights; hard/soft: against the "
       "ray-traced camera-view references over the receivers that face the light (ndl > 0); receivers with "
       "finite depth inside the light frustum only; acne / umbra_leak: receivers lit / shadowed in reference_hard "
       "at every counted receiver of their 7x7 window that come out below / above 0.5, as fractions of "
       "lit_inside / shadowed_inside\",\n"
    << "  \"results\": [\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const auto& o = r.options;
    f << "    {\"scene\": \"" << json_escape(r.scene) << "\", \"method\": \"" << r.method << "\", \"config\": \""
      << json_escape(r.label) << "\", \"parameters\": {\"blur_radius\": " << o.blur.radius << ", \"lookup\": \""
      << lookup_name(o.lookup.kind) << "\", \"storage\": \"" << storage_name(o.storage) << "\"";
    for (const MethodParameter& p : find_method(o.method).parameter_values(o))
      f << ", \"" << json_escape(p.key) << "\": " << p.value;
    f << "}, \"time_ms\": " << r.time_ms << ", \"min_ms\": " << r.min_ms << ", \"runs\": " << r.runs
      << ", \"stages_ms\": {\"transform\": " << r.stages.transform * 1e3 << ", \"blur\": " << r.stages.blur * 1e3
      << ", \"mips\": " << r.stages.pyramid * 1e3 << ", \"sat\": " << r.stages.sat * 1e3
      << ", \"zmax\": " << r.stages.zmax * 1e3 << ", \"reconstruct\": " << r.stages.reconstruct * 1e3
      << ", \"classify\": " << r.stages.classify * 1e3 << "}, \"device_bytes\": " << r.device_bytes << ", ";
    stats_json(f, "sref", r.sref);
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
  if (!f) throw InputError("cannot write '" + path + "'");
}

void write_pareto_png(const std::string& path, const std::string& scene, const std::vector<Row>& rows,
                      const std::string& metric) {
  namespace IBA = OIIO::ImageBufAlgo;
  const int W = 960, H = 640, L = 80, R = 180, T = 50, B = 60;  // plot area margins (legend right)
  OIIO::ImageBuf img(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::FLOAT));
  IBA::fill(img, {1.0f, 1.0f, 1.0f});
  if (rows.empty()) {
    img.write(path);
    return;
  }
  double tmin = INFINITY, tmax = 0, emax = 0;
  for (const auto& r : rows) {
    tmin = std::min(tmin, r.time_ms);
    tmax = std::max(tmax, r.time_ms);
    const double e = row_metric(r, metric);
    if (std::isfinite(e)) emax = std::max(emax, e);
  }
  tmin = std::max(tmin, 1e-3);
  const double lt0 = std::floor(std::log10(tmin) * 4) / 4,
               lt1 = std::ceil(std::log10(std::max(tmax, tmin * 1.01)) * 4) / 4;
  emax = emax > 0 ? emax * 1.08 : 1.0;
  auto px = [&](double t) {
    return int(L + (std::log10(std::max(t, 1e-3)) - lt0) / std::max(lt1 - lt0, 1e-6) * (W - L - R));
  };
  auto py = [&](double e) { return int(H - B - std::min(e, emax) / emax * (H - T - B)); };
  const std::vector<float> black{0, 0, 0}, grey{0.85f, 0.85f, 0.85f};
  // Grid: decades (and 2x, 5x) on time, fifths on error.
  for (int k = int(std::floor(lt0)); k <= int(std::ceil(lt1)); ++k)
    for (double m : {1.0, 2.0, 5.0}) {
      const double t = m * std::pow(10.0, k), lt = std::log10(t);
      if (lt < lt0 - 1e-9 || lt > lt1 + 1e-9) continue;
      const int x = px(t);
      IBA::render_line(img, x, T, x, H - B, grey);
      std::ostringstream s;
      s << t;
      text(img, x - 8, H - B + 18, s.str(), black, 13);
    }
  for (int k = 0; k <= 5; ++k) {
    const double e = emax * k / 5;
    const int y = py(e);
    IBA::render_line(img, L, y, W - R, y, grey);
    std::ostringstream s;
    s.precision(3);
    s << e;
    text(img, 8, y + 5, s.str(), black, 13);
  }
  IBA::render_box(img, L, T, W - R, H - B, black);
  text(img, L, 30, scene + ": time vs " + metric + " error (" + std::to_string(rows.size()) + " configurations)", black,
       18);
  text(img, (W - R) / 2 - 60, H - 15, "median time per frame, ms (log)", black, 14);
  // Pareto front.
  const auto front = pareto_front(rows, metric);
  for (size_t i = 1; i < front.size(); ++i) {
    const Row &a = rows[front[i - 1]], &b = rows[front[i]];
    IBA::render_line(img, px(a.time_ms), py(row_metric(a, metric)), px(b.time_ms), py(row_metric(a, metric)),
                     {0.2f, 0.2f, 0.2f});
    IBA::render_line(img, px(b.time_ms), py(row_metric(a, metric)), px(b.time_ms), py(row_metric(b, metric)),
                     {0.2f, 0.2f, 0.2f});
  }
  for (const auto& r : rows) {
    const int x = px(r.time_ms), y = py(row_metric(r, metric));
    IBA::render_box(img, x - 3, y - 3, x + 3, y + 3, method_colour(r.method), true);
  }
  for (size_t i : front) {  // circle-ish outline on front points + label
    const Row& r = rows[i];
    const int x = px(r.time_ms), y = py(row_metric(r, metric));
    IBA::render_box(img, x - 6, y - 6, x + 6, y + 6, black, false);
    text(img, x + 8, y - 8, r.label, black, 11);
  }
  // Legend.
  std::vector<std::string> seen;
  for (const auto& r : rows)
    if (std::find(seen.begin(), seen.end(), r.method) == seen.end()) seen.push_back(r.method);
  int ly = T + 10;
  for (const auto& m : seen) {
    IBA::render_box(img, W - R + 15, ly - 8, W - R + 25, ly + 2, method_colour(m), true);
    text(img, W - R + 32, ly + 2, m, black, 14);
    ly += 22;
  }
  text(img, W - R + 15, ly + 10, "box = Pareto front", black, 12);
  if (!img.write(path)) throw InputError("cannot write '" + path + "': " + img.geterror());
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

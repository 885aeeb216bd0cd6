// Flicker of a frame sequence (flicker.hpp).
#include "flicker.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cascade_io.hpp"
#include "drawing.hpp"
#include "eval_util.hpp"
#include "output_file.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {
namespace {

std::string key_of(const Row& r) { return r.method + "|" + r.label; }

// The world positions of a frame's view.exr (x y z per receiver), or none when it has no view.
std::vector<float> view_positions(const Scene& scene) {
  if (scene.dir.empty()) return {};  // a scene from memory
  const std::filesystem::path file = std::filesystem::path(scene.dir) / "view.exr";
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return {};
  const ViewReceivers v = io::load_view_receivers(file.string());
  std::vector<float> p;
  p.reserve(3 * v.count());
  for (size_t i = 0; i < v.count(); ++i) p.insert(p.end(), {v.x[i], v.y[i], v.z[i]});
  return p;
}

bool same_positions(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  return true;
}

// Configurations no other beats on both flicker and error (ties kept), by flicker.
std::vector<size_t> front_of(const std::vector<FlickerRow>& rows, const std::vector<size_t>& shown) {
  std::vector<size_t> front;
  for (size_t i : shown) {
    bool beaten = false;
    for (size_t j : shown)
      beaten |= j != i && rows[j].flicker <= rows[i].flicker && rows[j].rmse <= rows[i].rmse &&
                (rows[j].flicker < rows[i].flicker || rows[j].rmse < rows[i].rmse);
    if (!beaten) front.push_back(i);
  }
  std::sort(front.begin(), front.end(), [&](size_t a, size_t b) { return rows[a].flicker < rows[b].flicker; });
  return front;
}

}  // namespace

void FlickerTracker::check_frame(const Scene& scene) {
  const std::string where = "--frames: frame '" + scene.dir + "'";
  if (checked_ == 0) {
    width_ = scene.receivers.width;
    height_ = scene.receivers.height;
    soft_ = !scene.ref_soft.data.empty();
    first_dir_ = scene.dir;
    view_ = view_positions(scene);
    if (!soft_ && scene.ref_hard.data.empty())
      throw InputError(where +
                       " has neither reference_soft.exr nor reference_hard.exr: flicker is measured against one");
  } else {
    if (scene.receivers.width != width_ || scene.receivers.height != height_)
      throw InputError(where + " has " + std::to_string(scene.receivers.width) + "x" +
                       std::to_string(scene.receivers.height) + " receivers, the first frame '" + first_dir_ + "' " +
                       std::to_string(width_) + "x" + std::to_string(height_) +
                       ": the frames of a sequence share one camera");
    if ((soft_ ? scene.ref_soft : scene.ref_hard).data.empty())
      throw InputError(where + " has no " + (soft_ ? "reference_soft.exr" : "reference_hard.exr") +
                       ", which the first frame measured against");
    if (!view_.empty()) {
      const std::vector<float> here = view_positions(scene);
      if (!here.empty() && !same_positions(here, view_))
        throw InputError(where +
                         " sees other world points than the first frame (its view.exr differs): flicker "
                         "is measured from one still camera");
    }
  }
  ++checked_;
}

void FlickerTracker::add_frame(const Scene& scene, const std::vector<Row>& rows) {
  if (checked_ == frames_) check_frame(scene);
  const std::vector<float>& ref = soft_ ? scene.ref_soft.data : scene.ref_hard.data;
  const size_t n = scene.receivers.count();
  for (const Row& r : rows) {
    if (r.visibility.size() != n || ref.size() != n) continue;
    const std::string key = key_of(r);
    auto [it, fresh] = tracks_.try_emplace(key);
    Track& t = it->second;
    if (fresh) {
      order_.push_back(key);
      t.row.method = r.method;
      t.row.label = r.label;
    }
    std::vector<float> error(n, NAN);
    for (size_t i = 0; i < n; ++i)
      if (scene.traced[i]) error[i] = r.visibility[i] - ref[i];
    // A pair only of consecutive frames (a configuration skipped in a frame starts again).
    if (t.last_frame == frames_ - 1 && !t.last_error.empty()) {
      double sum = 0;
      size_t count = 0;
      for (size_t i = 0; i < n; ++i)
        if (std::isfinite(error[i]) && std::isfinite(t.last_error[i]))
          sum += std::abs(double(error[i]) - t.last_error[i]), ++count;
      t.flicker_sum += count ? sum / count : 0.0;
      ++t.pairs;
    }
    const ErrorStats& e = soft_ ? r.soft : r.hard;
    t.rmse_sum += e.valid ? e.rmse : 0.0;
    t.times.push_back(r.time_ms);
    ++t.row.frames;
    t.last_error = std::move(error);
    t.last_frame = frames_;
  }
  ++frames_;
}

std::vector<FlickerRow> FlickerTracker::rows() const {
  std::vector<FlickerRow> out;
  for (const std::string& key : order_) {
    const Track& t = tracks_.at(key);
    FlickerRow r = t.row;
    r.rmse = r.frames ? t.rmse_sum / r.frames : 0.0;
    r.flicker = t.pairs ? t.flicker_sum / t.pairs : -1.0;
    r.time_ms = detail::median(t.times);
    out.push_back(r);
  }
  return out;
}

void write_flicker_csv(const std::string& path, const std::vector<FlickerRow>& rows, const std::string& reference) {
  std::ostringstream f;
  f.precision(6);
  f << "method,config,frames,rmse_" << reference << ",flicker_" << reference << ",time_ms\n";
  for (const FlickerRow& r : rows)
    f << r.method << ",\"" << r.label << "\"," << r.frames << "," << r.rmse << "," << r.flicker << "," << r.time_ms
      << "\n";
  io::write_text(path, "results file", f.str());
}

std::string flicker_markdown(const std::vector<FlickerRow>& rows, const std::string& reference) {
  std::ostringstream s;
  s << "| method | configuration | frames | RMSE " << reference << " (mean) | flicker " << reference
    << " (mean) | ms (median) |\n|---|---|---|---|---|---|\n";
  for (const FlickerRow& r : rows)
    s << "| " << r.method << " | " << r.label << " | " << r.frames << " | " << detail::fmt(r.rmse, 4) << " | "
      << (r.flicker < 0 ? std::string("-") : detail::fmt(r.flicker, 4)) << " | " << detail::fmt(r.time_ms, 4) << " |\n";
  return s.str();
}

void write_flicker_png(const std::string& path, const std::vector<FlickerRow>& rows, const std::string& reference,
                       int frames) {
  namespace IBA = OIIO::ImageBufAlgo;
  using draw::text;
  const int W = 1200, H = 700, L = 80, R = 180, T = 90, B = 60;
  OIIO::ImageBuf img(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::FLOAT));
  IBA::fill(img, {1.0f, 1.0f, 1.0f});
  const std::vector<float> black{0, 0, 0}, grey{0.85f, 0.85f, 0.85f}, dim{0.35f, 0.35f, 0.35f};
  const std::string title = "flicker vs RMSE against the " + reference + " reference, " + std::to_string(frames) +
                            " frames from one still camera";
  const std::string subtitle = "flicker: mean |e(t) - e(t-1)| per frame pair, e = v - reference_" + reference +
                               "; RMSE: mean over frames; one point per configuration";
  text(img, 12, 26, title, black, 17);
  text(img, 12, 48, subtitle, dim, 13);
  text(img, L, T - 12, "RMSE", black, 13);
  text(img, (L + W - R) / 2 - 20, H - 15, "flicker", black, 14);
  std::vector<size_t> shown;
  double fmax = 0, emax = 0;
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i].flicker >= 0 && std::isfinite(rows[i].flicker) && std::isfinite(rows[i].rmse)) {
      shown.push_back(i);
      fmax = std::max(fmax, rows[i].flicker);
      emax = std::max(emax, rows[i].rmse);
    }
  fmax = fmax > 0 ? fmax * 1.05 : 1.0;
  emax = emax > 0 ? emax * 1.05 : 1.0;
  const auto px = [&](double f) { return int(L + f / fmax * (W - L - R)); };
  const auto py = [&](double e) { return int(H - B - e / emax * (H - T - B)); };
  for (int k = 0; k <= 5; ++k) {
    const int x = px(fmax * k / 5), y = py(emax * k / 5);
    IBA::render_line(img, x, T, x, H - B, grey);
    IBA::render_line(img, L, y, W - R, y, grey);
    text(img, x - 8, H - B + 18, detail::fmt(fmax * k / 5, 3), black, 13);
    text(img, 8, y + 5, detail::fmt(emax * k / 5, 3), black, 13);
  }
  IBA::render_box(img, L, T, W - R, H - B, black);
  std::vector<std::string> methods;
  for (size_t i : shown) {
    const int x = px(rows[i].flicker), y = py(rows[i].rmse);
    IBA::render_box(img, x - 3, y - 3, x + 3, y + 3, draw::method_colour(rows[i].method), true);
    if (std::find(methods.begin(), methods.end(), rows[i].method) == methods.end()) methods.push_back(rows[i].method);
  }
  int line = 0;
  for (size_t i : front_of(rows, shown)) {
    const int x = px(rows[i].flicker), y = py(rows[i].rmse);
    IBA::render_box(img, x - 6, y - 6, x + 6, y + 6, black, false);
    text(img, x + 8, y - 8 + 14 * (line++ % 2), rows[i].label, black, 11);
  }
  for (size_t k = 0; k < methods.size(); ++k) {
    const int y = T + 10 + 20 * int(k);
    IBA::render_box(img, W - R + 15, y - 8, W - R + 27, y + 4, draw::method_colour(methods[k]), true);
    text(img, W - R + 34, y + 3, methods[k], black, 13);
  }
  draw::write_png8(path, img, title + "\n" + subtitle);
}

}  // namespace sf::eval

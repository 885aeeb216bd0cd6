// The contact sheet of a scene: the reference beside each method's best configuration, each with
// its signed error map beneath, so that a reader sees where a method darkens or leaks.
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "drawing.hpp"
#include "evaluate.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {
namespace {

constexpr int kMargin = 10, kTitleBand = 56, kLabelBand = 36, kGap = 4, kLegendBand = 64;
constexpr int kMinCellWidth = 260;   // room for a label such as "msm-hausdorff R=3 mips f32"
constexpr int kMinSheetWidth = 720;  // room for the legend
constexpr size_t kMaxColumns = 5;

// Receivers no figure counts (background, outside the frustum, facing away from the light for
// the ray-traced references): a muted green, outside both the grey scale and the error scale.
const float kNoReceiver[3] = {0.55f, 0.68f, 0.55f};

// Diverging scale: white at 0, blue towards -scale (darker than the reference), red towards
// +scale (brighter: light leaks); saturated beyond.
void error_colour(double e, float* rgb) {
  const double t = std::clamp(std::isfinite(e) ? e / kContactErrorScale : 1.0, -1.0, 1.0);
  static const float blue[3] = {0.10f, 0.30f, 0.90f}, red[3] = {0.85f, 0.10f, 0.10f};
  const float* end = t < 0 ? blue : red;
  const float a = float(std::abs(t));
  for (int c = 0; c < 3; ++c) rgb[c] = (1.0f - a) + a * end[c];
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

int ContactLayout::cell_x(size_t k) const { return kMargin + int(k % size_t(columns)) * (cell_w + kMargin); }
int ContactLayout::cell_y(size_t k) const { return kTitleBand + int(k / size_t(columns)) * (cell_h + kMargin); }

ContactLayout contact_layout(int receivers_w, int receivers_h, size_t tiles) {
  if (receivers_w <= 0 || receivers_h <= 0 || tiles == 0) throw InputError("contact sheet: nothing to show");
  ContactLayout l;
  l.shrink = (receivers_w + kContactTileWidth - 1) / kContactTileWidth;
  l.tile_w = (receivers_w + l.shrink - 1) / l.shrink;
  l.tile_h = (receivers_h + l.shrink - 1) / l.shrink;
  l.columns = int(std::min(tiles, kMaxColumns));
  l.rows = int((tiles + size_t(l.columns) - 1) / size_t(l.columns));
  l.cell_w = std::max(l.tile_w, kMinCellWidth);
  l.cell_h = kLabelBand + l.tile_h + kGap + l.tile_h;
  l.width = std::max(kMargin + l.columns * (l.cell_w + kMargin), kMinSheetWidth);
  l.height = kTitleBand + l.rows * (l.cell_h + kMargin) + kLegendBand;
  return l;
}

Reference contact_reference(const Scene& s, Reference plot_ref) {
  if (plot_ref == Reference::Self) return has_reference(s, Reference::Soft) ? Reference::Soft : Reference::Target;
  return plot_reference(s, plot_ref, nullptr);
}

std::vector<size_t> best_per_method(const std::vector<Row>& rows, Reference ref, const std::string& metric) {
  std::vector<size_t> best;
  for (size_t i = 0; i < rows.size(); ++i) {
    const double e = row_error(rows[i], ref, metric);
    if (!std::isfinite(e)) continue;
    auto it = std::find_if(best.begin(), best.end(), [&](size_t b) { return rows[b].method == rows[i].method; });
    if (it == best.end()) {
      best.push_back(i);
      continue;
    }
    const double eb = row_error(rows[*it], ref, metric);
    if (e < eb || (e == eb && rows[i].time_ms < rows[*it].time_ms)) *it = i;
  }
  return best;
}

void write_contact_sheet(const std::string& path, const Scene& scene, const std::vector<Row>& rows,
                         const std::vector<size_t>& best, Reference ref, const std::string& metric,
                         const TargetFilter& target, const std::vector<double>& target_ref) {
  namespace IBA = OIIO::ImageBufAlgo;
  using draw::text;
  const Receivers& rx = scene.receivers;
  const size_t n = rx.count();
  std::vector<double> reference(n, 0.0);
  const bool traced = ref == Reference::Soft || ref == Reference::Hard;
  if (traced) {
    if (!has_reference(scene, ref)) throw InputError("contact sheet: scene '" + scene.name + "' lacks the reference");
    const HostImage& img = ref == Reference::Soft ? scene.ref_soft : scene.ref_hard;
    std::copy(img.data.begin(), img.data.end(), reference.begin());
  } else {
    if (ref == Reference::Self || target_ref.size() != n)
      throw InputError("contact sheet: needs one reference picture (soft, hard or the target's s_ref)");
    reference = target_ref;
  }
  const std::vector<uint8_t>& mask = traced ? scene.traced : scene.valid;

  const ContactLayout L = contact_layout(rx.width, rx.height, best.size() + 1);
  OIIO::ImageBuf img(OIIO::ImageSpec(L.width, L.height, 3, OIIO::TypeDesc::FLOAT));
  IBA::fill(img, {1.0f, 1.0f, 1.0f});
  const std::vector<float> black{0, 0, 0}, dim{0.35f, 0.35f, 0.35f};

  // A tile reduced by L.shrink: the picture shows the mean over each block's counted receivers,
  // the error map the error of largest magnitude in it (a one-receiver leak stays visible).
  auto draw_tile = [&](int x0, int y0, const std::vector<float>* v, bool error) {
    const int s = L.shrink;
    for (int ty = 0; ty < L.tile_h; ++ty)
      for (int tx = 0; tx < L.tile_w; ++tx) {
        double sum = 0, worst = 0;
        int count = 0;
        for (int y = ty * s; y < std::min((ty + 1) * s, rx.height); ++y)
          for (int x = tx * s; x < std::min((tx + 1) * s, rx.width); ++x) {
            const size_t i = size_t(y) * size_t(rx.width) + size_t(x);
            if (!mask[i]) continue;
            const double value = v ? double((*v)[i]) : reference[i];
            const double e = std::isfinite(value) ? value - reference[i] : 1.0;  // NaN: the worst error
            if (count == 0 || std::abs(e) > std::abs(worst)) worst = e;
            sum += std::isfinite(value) ? value : 0.0;
            ++count;
          }
        float rgb[3] = {kNoReceiver[0], kNoReceiver[1], kNoReceiver[2]};
        if (count && error) {
          error_colour(worst, rgb);
        } else if (count) {
          rgb[0] = rgb[1] = rgb[2] = float(std::clamp(sum / count, 0.0, 1.0));
        }
        img.setpixel(x0 + tx, y0 + ty, rgb, 3);
      }
  };

  const std::string mtext = metric_text(metric);
  text(img, kMargin, 24,
       scene.name + ": each method's configuration of lowest " + mtext + " against " + reference_text(ref, target),
       black, 16);
  std::string sub = "top: visibility; beneath: output - reference (blue darker, red brighter, white equal)";
  if (L.shrink > 1)
    sub += "; shown 1:" + std::to_string(L.shrink) + " (pictures: block mean; errors: the largest in each block)";
  text(img, kMargin, 44, sub, dim, 12);

  for (size_t k = 0; k <= best.size(); ++k) {
    const int x = L.cell_x(k), y = L.cell_y(k);
    const int pic_y = y + kLabelBand, err_y = pic_y + L.tile_h + kGap;
    if (k == 0) {
      text(img, x, y + 14, "reference", black, 13);
      text(img, x, y + 30, reference_text(ref, target), dim, 11);
      draw_tile(x, pic_y, nullptr, false);
      // The slot beneath the reference (no error map of its own) says how to read the others.
      if (L.tile_h >= 80) {
        const char* lines[] = {"beneath each output: output - reference", "blue: darker than the reference",
                               "red: brighter (light leaks)", "white: equal; scale at the bottom"};
        for (int k = 0; k < 4; ++k) text(img, x + 4, err_y + 18 + 18 * k, lines[k], dim, 12);
      }
      continue;
    }
    const Row& r = rows[best[k - 1]];
    if (r.visibility.size() != n) throw InputError("contact sheet: row '" + r.label + "' kept no visibility");
    text(img, x, y + 14, r.label, draw::method_colour(r.method), 13);
    text(img, x, y + 30, mtext + " " + fixed(row_error(r, ref, metric), 3) + ", " + fixed(r.time_ms, 2) + " ms", dim,
         11);
    draw_tile(x, pic_y, &r.visibility, false);
    draw_tile(x, err_y, &r.visibility, true);
  }

  // Legend: the error scale with its numbers, and the colour of receivers no figure counts.
  const int ly = L.height - kLegendBand + 8, bar_w = 300, bar_h = 14;
  for (int px = 0; px < bar_w; ++px) {
    float rgb[3];
    error_colour((2.0 * (px + 0.5) / bar_w - 1.0) * kContactErrorScale, rgb);
    IBA::fill(img, {rgb[0], rgb[1], rgb[2]}, OIIO::ROI(kMargin + px, kMargin + px + 1, ly, ly + bar_h));
  }
  IBA::render_box(img, kMargin, ly, kMargin + bar_w - 1, ly + bar_h, black);
  for (int k = 0; k <= 4; ++k) {
    const double e = (k - 2) * kContactErrorScale / 2;
    const int tx = kMargin + k * (bar_w - 1) / 4;
    IBA::render_line(img, tx, ly + bar_h, tx, ly + bar_h + 4, black);
    const std::string s = (k == 0 ? "<= " : k == 4 ? ">= " : "") + fixed(e, 3);
    const int w = draw::text_width(s, 11);
    text(img, std::clamp(tx - w / 2, 2, kMargin + bar_w + 10 - w), ly + bar_h + 17, s, black, 11);
  }
  text(img, kMargin + bar_w + 14, ly + 12, "output - reference", black, 12);
  const int sx = kMargin + bar_w + 14, sy = ly + 22;
  IBA::fill(img, {kNoReceiver[0], kNoReceiver[1], kNoReceiver[2]}, OIIO::ROI(sx, sx + 14, sy, sy + 14));
  text(img, sx + 20, sy + 12, traced ? "no receiver counted (background, facing away)" : "no receiver counted", black,
       12);
  draw::write_png8(path, img,
                   scene.name + ": contact sheet, " + mtext + " against " + reference_text(ref, target) + "\n" + sub);
}

}  // namespace sf::eval

#include "preview_images.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "shadowfilter/errors.hpp"

namespace sf::cli {
namespace {

// Grey albedo, the ambient share that keeps shadowed shapes visible, and the background's colour
// (a muted sky blue: apart from every grey a lit or shadowed surface can take).
constexpr float kAlbedo = 0.8f;
constexpr float kAmbient = 0.15f;
constexpr float kBackground[3] = {0.42f, 0.58f, 0.78f};

}  // namespace

PreviewKind parse_preview(const std::string& value) {
  if (value == "none") return PreviewKind::None;
  if (value.empty() || value == "plain") return PreviewKind::Plain;
  if (value == "shaded") return PreviewKind::Shaded;
  throw InputError("--preview takes no value, plain or shaded, got '" + value + "'");
}

std::vector<std::string> preview_paths(const std::string& output, PreviewKind kind) {
  if (kind == PreviewKind::None) return {};
  const std::string plain = io::preview_path(output);
  if (kind == PreviewKind::Plain) return {plain};
  std::filesystem::path shaded(plain);
  shaded.replace_filename(shaded.stem().string() + "_shaded.png");
  return {plain, shaded.string()};
}

HostImage shaded_preview(const HostImage& vis, const std::vector<float>& probe, const std::vector<float>& ndl) {
  HostImage out(vis.width, vis.height, 3);
  for (size_t i = 0; i < vis.texels(); ++i) {
    float* rgb = &out.data[i * 3];
    if (i >= probe.size() || !std::isfinite(probe[i])) {
      std::copy(kBackground, kBackground + 3, rgb);
      continue;
    }
    const float n = i < ndl.size() && std::isfinite(ndl[i]) ? std::max(ndl[i], 0.0f) : 1.0f;
    const float v = std::clamp(vis.data[i * size_t(vis.channels)], 0.0f, 1.0f);
    const float grey = kAlbedo * (kAmbient + (1.0f - kAmbient) * v * n);
    std::fill(rgb, rgb + 3, grey);
  }
  return out;
}

std::vector<io::ImageToWrite> output_with_previews(const std::string& output, const HostImage& visibility,
                                                   PreviewKind kind, const std::vector<float>& probe,
                                                   const std::vector<float>& ndl, HostImage* keep) {
  std::vector<io::ImageToWrite> images{{output, &visibility}};
  const std::vector<std::string> paths = preview_paths(output, kind);
  if (!paths.empty()) images.push_back({paths[0], &visibility});
  if (paths.size() > 1) {
    *keep = shaded_preview(visibility, probe, ndl);
    images.push_back({paths[1], keep});
  }
  return images;
}

}  // namespace sf::cli

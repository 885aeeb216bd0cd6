#pragma once
// Plain host-side images shared by the I/O layer, the reference and the CLI.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace sf {

// An interleaved float image: texel (x, y) channel c is data[(y * width + x) * channels + c].
// Row y = 0 is the first row of the file.
struct HostImage {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<float> data;
  std::vector<std::string> channel_names;  // optional; empty = default names
  // Optional per-channel storage when writing EXR: "float" (default) or "half".
  std::vector<std::string> channel_formats;
  // Header metadata written as string attributes (e.g. near/far of a generated scene).
  std::map<std::string, std::string> attributes;

  HostImage() = default;
  HostImage(int w, int h, int c = 1, float fill = 0.0f)
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}
  size_t texels() const { return static_cast<size_t>(width) * height; }
  float& at(int x, int y, int c = 0) { return data[(static_cast<size_t>(y) * width + x) * channels + c]; }
  float at(int x, int y, int c = 0) const { return data[(static_cast<size_t>(y) * width + x) * channels + c]; }
};

// Receiver samples as structure-of-arrays (what the reconstruction kernels read).
// u, v: shadow-map texture coordinates; d: light-space depth (linear, [0,1]; NaN = background);
// f: footprint in level-0 texels (1 when the input has none); ndl: cosine between the surface
// normal (oriented towards the viewer) and the direction to the light, <= 0 facing away from the
// light (empty when the input has none). No kernel reads ndl: sf::filter shadows facing-away
// receivers with it, and evaluate leaves them out of its ray-traced error figures.
// nx, ny, nz: the normal in light space scaled to one texel (normal_offset.hpp): the change of
// (u W, v H, d) when the receiver moves one texel's world width along its normal; the normal
// offset moves each lookup along it (FilterOptions::normal_offset). NaN = unknown (no offset).
struct Receivers {
  int width = 0;  // output image size (receiver image size, or shadow-map size)
  int height = 0;
  bool grid = false;  // true: --receiver-depth mode, u/v are the texel centres of a WxH grid
  bool has_footprint = false;
  bool has_ndl = false;
  std::vector<float> u, v, d, f;  // u, v, f empty in grid mode
  std::vector<float> ndl;         // empty unless has_ndl; NaN = unknown
  bool has_normal = false;
  std::vector<float> nx, ny, nz;  // empty unless has_normal; NaN = unknown
  // dudx dvdx dudy dvdy: the Jacobian of (u W, v H) over the image's pixels, level-0 texels per
  // pixel (footprint.hpp): footprint lookups follow it up to LookupOptions::max_anisotropy.
  // f is then its isotropic footprint. Empty unless has_jacobian.
  bool has_jacobian = false;
  std::vector<float> dudx, dvdx, dudy, dvdy;
  size_t count() const { return static_cast<size_t>(width) * height; }
};

// Camera-view receivers of a layered run (cascades.hpp, methods.md sec. 6), structure of arrays:
// world position of the surface seen through each pixel (NaN on background), its view depth
// (distance along the camera's axis, which picks the layer) and the world offsets across the
// pixel (the tangent-plane points half a pixel to either side: what a footprint in any layer's
// texels is computed from, through that layer's Jacobian). Image order, row-major.
struct ViewReceivers {
  int width = 0;
  int height = 0;
  std::vector<float> x, y, z;        // world position
  std::vector<float> depth;          // view depth
  std::vector<float> dxx, dxy, dxz;  // world offset across the pixel along the image's x
  std::vector<float> dyx, dyy, dyz;  // ... along the image's y
  std::vector<float> ndl;            // empty unless present; NaN = unknown (as Receivers::ndl)
  size_t count() const { return static_cast<size_t>(width) * height; }
};

}  // namespace sf

#pragma once
// Lat-long environment maps for distant light (Ritschel 2007 sec. 4.1 and 5.1; docs/coherent_render.md):
// the map as RGB float radiance, its luminance-proportional sampling tables (what
// kernels/coherent/render.cl reads), a host twin of the kernel's sampling, and a synthetic
// sky so that the repository needs no downloaded HDR.
//
// Convention (the same as the coherent stack's view grid, shadowfilter/coherent.hpp): texel
// (x, y) covers polar angles theta in [y, y + 1] pi / height from +y (row 0 at the zenith) and
// azimuths phi in [x, x + 1] 2 pi / width, direction (sin t cos p, cos t, sin t sin p). Radiance is
// constant over a texel (nearest lookup), so the map is exactly the function its sampling
// distribution is proportional to.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "shadowfilter/host_image.hpp"

namespace sf::scene {

struct EnvMap {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 per texel, row-major, row 0 at the zenith
  // Sampling tables, float because the kernel reads them as they are (the host twin too): a texel
  // is drawn with probability (marginal[y + 1] - marginal[y]) (conditional[y (w + 1) + x + 1] -
  // conditional[y (w + 1) + x]), proportional to its luminance times its solid angle, and the
  // direction is uniform in solid angle within the texel (cos theta uniform between
  // row_cos[y] and row_cos[y + 1], phi uniform across the column). pdf in solid angle: that
  // probability / texel_solid_angle[y]. No division by sin theta, so nothing blows up at the poles.
  std::vector<float> marginal;           // height + 1, marginal[0] = 0, marginal[height] = 1
  std::vector<float> conditional;        // height * (width + 1), each row from 0 to 1
  std::vector<float> row_cos;            // height + 1: cos of the row boundaries
  std::vector<float> texel_solid_angle;  // height: the solid angle of one texel of row y
  bool sampled = false;                  // false: the map is black (no env samples are drawn)
  double power = 0.0;                    // sum of luminance times solid angle (the integral)

  float luminance(int x, int y) const;
  std::array<float, 3> texel(int x, int y) const {
    const float* c = &rgb[(size_t(y) * width + x) * 3];
    return {c[0], c[1], c[2]};
  }
};

// Rec. 709 luminance: the weight the sampling distribution is proportional to.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// A map from radiance values (3 per texel, row 0 at the zenith) with its sampling tables.
// InputError (one line, naming `what` and the texel) on an empty size or a NaN, Inf, negative or
// larger than kMaxRadiance texel.
inline constexpr float kMaxRadiance = 1e20f;  // sums of S samples stay far from float overflow
EnvMap make_envmap(int width, int height, std::vector<float> rgb, const std::string& what);
// Reads a lat-long map with OpenImageIO (EXR, HDR, PFM, TIFF, ...): 1 channel (grey), 3 (RGB) or
// 4 (RGB, alpha ignored). InputError on anything but a regular file, a declared size over the
// memory budget (io::image_memory_budget), an unreadable or truncated file, another channel
// count and the texels make_envmap refuses.
EnvMap load_envmap(const std::string& path);
// A constant map (the white furnace): every texel `value`.
EnvMap uniform_envmap(int width, int height, float value);

// One direction drawn from the map (host twin of sf_env_sample in coherent/render.cl, same float
// arithmetic): u0 picks the row, u1 the column, their remainders the point within the texel.
struct EnvSample {
  std::array<float, 3> dir;
  float pdf = 0.0f;  // solid angle
  int x = 0, y = 0;  // the texel it lies in
};
EnvSample sample_envmap(const EnvMap& env, float u0, float u1);
// The solid-angle pdf of a direction inside texel (x, y).
float envmap_pdf(const EnvMap& env, int x, int y);
// The texel whose cell holds direction d (any length > 0).
void envmap_texel_of(const EnvMap& env, const std::array<float, 3>& d, int* x, int* y);

// The synthetic sky: a gradient from a warm horizon to a blue zenith, a dark ground below the
// horizon and a sun disc (anti-aliased by 4x4 supersampling), deterministic. Elevation and
// azimuth in degrees (azimuth phi from +x toward +z), the disc's angular radius in degrees.
struct SkyOptions {
  int width = 256, height = 128;
  double sun_elevation = 40.0, sun_azimuth = 60.0, sun_radius = 2.5;
  double sun_radiance = 400.0;  // the disc's R (G and B a little lower: a warm sun)
};
HostImage synthetic_sky(const SkyOptions& options);  // RGB, half-float channels for EXR
// The map of an image (3 channels), e.g. of synthetic_sky.
EnvMap envmap_from_image(const HostImage& image, const std::string& what);

}  // namespace sf::scene

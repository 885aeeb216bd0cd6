#include "envmap.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "input_file.hpp"
#include "io_detail.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

[[noreturn]] void fail(const std::string& what, const std::string& problem) {
  throw InputError("environment map '" + what + "': " + one_line(problem));
}

// The index j in [0, n - 1] with cdf[j] <= u < cdf[j + 1] (cdf[0] = 0 <= u < 1 = cdf[n]): rows and
// columns of zero probability are never chosen. The kernel's sf_env_search is the same loop.
int search(const float* cdf, int n, float u) {
  int lo = 0, hi = n;
  while (hi - lo > 1) {
    const int mid = (lo + hi) >> 1;
    if (cdf[mid] <= u)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

// The largest float below 1: remainders stay inside their cell.
constexpr float kBelowOne = 0x1.fffffep-1f;

}  // namespace

float EnvMap::luminance(int x, int y) const {
  const std::array<float, 3> c = texel(x, y);
  return sf::scene::luminance(c[0], c[1], c[2]);
}

EnvMap make_envmap(int width, int height, std::vector<float> rgb, const std::string& what) {
  if (width <= 0 || height <= 0) fail(what, "empty map (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (long(width) * height > (1L << 26)) fail(what, "larger than 2^26 texels");
  if (rgb.size() != size_t(width) * height * 3) fail(what, "holds " + std::to_string(rgb.size()) + " values");
  for (size_t i = 0; i < rgb.size(); ++i) {
    const float v = rgb[i];
    if (!std::isfinite(v) || v < 0.0f || v > kMaxRadiance) {
      const size_t t = i / 3;
      fail(what, "texel (x=" + std::to_string(t % width) + ", y=" + std::to_string(t / width) + ") channel " +
                     std::to_string(i % 3) + " is " + std::to_string(v) +
                     "; radiance must be finite, >= 0 and <= 1e20");
    }
  }
  EnvMap env;
  env.width = width;
  env.height = height;
  env.rgb = std::move(rgb);
  env.row_cos.resize(size_t(height) + 1);
  for (int y = 0; y <= height; ++y) env.row_cos[y] = float(std::cos(kPi * y / height));
  env.row_cos[0] = 1.0f;
  env.row_cos[height] = -1.0f;
  env.texel_solid_angle.resize(height);
  std::vector<double> row_weight(height, 0.0);
  env.conditional.assign(size_t(height) * (width + 1), 0.0f);
  for (int y = 0; y < height; ++y) {
    // The texel's exact solid angle, from the float boundaries the sampler interpolates between
    // (so the pdf below is the density the sampler really draws with).
    const double omega = (double(env.row_cos[y]) - double(env.row_cos[y + 1])) * 2.0 * kPi / width;
    env.texel_solid_angle[y] = float(omega);
    std::vector<double> cdf(size_t(width) + 1, 0.0);
    for (int x = 0; x < width; ++x) cdf[x + 1] = cdf[x] + double(env.luminance(x, y)) * omega;
    row_weight[y] = cdf[width];
    float* row = &env.conditional[size_t(y) * (width + 1)];
    for (int x = 0; x <= width; ++x)
      // A black row is never drawn; a uniform table keeps its entries well defined.
      row[x] = cdf[width] > 0.0 ? float(cdf[x] / cdf[width]) : float(double(x) / width);
    row[width] = 1.0f;
  }
  env.marginal.assign(size_t(height) + 1, 0.0f);
  double total = 0.0;
  for (int y = 0; y < height; ++y) total += row_weight[y];
  env.power = total;
  env.sampled = total > 0.0;
  double acc = 0.0;
  for (int y = 0; y < height; ++y) {
    acc += row_weight[y];
    env.marginal[y + 1] = env.sampled ? float(acc / total) : float(double(y + 1) / height);
  }
  env.marginal[height] = 1.0f;
  return env;
}

EnvMap uniform_envmap(int width, int height, float value) {
  return make_envmap(width, height, std::vector<float>(size_t(width) * height * 3, value), "uniform");
}

EnvMap envmap_from_image(const HostImage& image, const std::string& what) {
  if (image.channels != 3) fail(what, "needs 3 channels, has " + std::to_string(image.channels));
  return make_envmap(image.width, image.height, image.data, what);
}

// The pixels come from the image reader (io_detail.hpp): only a regular file, its declared size
// within the memory budget and the file's size, every read checked. Channels: 1 (grey), 3 (RGB)
// or 4 (RGB and an alpha that is ignored); other counts have no agreed meaning as radiance.
EnvMap load_envmap(const std::string& path) {
  const io::detail::RawImage raw = io::detail::read_raw(path, "environment map");
  if (raw.channels != 1 && raw.channels != 3 && raw.channels != 4)
    fail(path, "has " + std::to_string(raw.channels) + " channels; needs 1 (grey), 3 (RGB) or 4 (RGBA)");
  return io::with_out_of_memory_named(path, "environment map", [&] {
    std::vector<float> rgb(raw.texels() * 3);
    for (size_t t = 0; t < raw.texels(); ++t)
      for (int c = 0; c < 3; ++c) rgb[t * 3 + c] = raw.at(t, raw.channels == 1 ? 0 : c);
    return make_envmap(raw.width, raw.height, std::move(rgb), path);
  });
}

EnvSample sample_envmap(const EnvMap& env, float u0, float u1) {
  const int W = env.width, H = env.height;
  EnvSample s;
  const int y = search(env.marginal.data(), H, u0);
  const float py = env.marginal[y + 1] - env.marginal[y];
  const float* row = &env.conditional[size_t(y) * (W + 1)];
  const int x = search(row, W, u1);
  const float px = row[x + 1] - row[x];
  // The remainders, rescaled to [0, 1): the point within the texel.
  const float ry = std::min((u0 - env.marginal[y]) / py, kBelowOne);
  const float rx = std::min((u1 - row[x]) / px, kBelowOne);
  const float c0 = env.row_cos[y], c1 = env.row_cos[y + 1];
  const float ct = c0 + (c1 - c0) * ry;
  const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
  const float phi = (float(x) + rx) * (6.28318530717958647f / float(W));
  s.dir = {st * std::cos(phi), ct, st * std::sin(phi)};
  s.pdf = py * px / env.texel_solid_angle[y];
  s.x = x;
  s.y = y;
  return s;
}

float envmap_pdf(const EnvMap& env, int x, int y) {
  const float* row = &env.conditional[size_t(y) * (env.width + 1)];
  return (env.marginal[y + 1] - env.marginal[y]) * (row[x + 1] - row[x]) / env.texel_solid_angle[y];
}

void envmap_texel_of(const EnvMap& env, const std::array<float, 3>& d, int* x, int* y) {
  const double n = std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]);
  const double t = std::acos(std::clamp(d[1] / n, -1.0, 1.0));
  double p = std::atan2(double(d[2]), double(d[0]));
  if (p < 0.0) p += 2.0 * kPi;
  *y = std::clamp(int(t / kPi * env.height), 0, env.height - 1);
  *x = std::clamp(int(p / (2.0 * kPi) * env.width), 0, env.width - 1);
}

HostImage synthetic_sky(const SkyOptions& o) {
  if (o.width < 4 || o.height < 2 || o.width > 8192 || o.height > 4096)
    throw InputError("sky: size must be within 4x2 .. 8192x4096, got " + std::to_string(o.width) + "x" +
                     std::to_string(o.height));
  for (double v : {o.sun_elevation, o.sun_azimuth, o.sun_radius, o.sun_radiance})
    if (!std::isfinite(v)) throw InputError("sky: sun parameters must be finite");
  if (!(o.sun_elevation >= -90.0 && o.sun_elevation <= 90.0))
    throw InputError("sky: --sun-elevation must lie in [-90, 90] degrees");
  if (o.sun_radius <= 0.0 || o.sun_radius > 45.0 || o.sun_radiance < 0.0 || o.sun_radiance > 60000.0)
    throw InputError("sky: sun radius must be in (0, 45] degrees and its radiance in [0, 60000] (half floats)");
  const double deg = kPi / 180.0;
  const double se = o.sun_elevation * deg, sa = o.sun_azimuth * deg;
  const double sun[3] = {std::cos(se) * std::cos(sa), std::sin(se), std::cos(se) * std::sin(sa)};
  const double cos_radius = std::cos(o.sun_radius * deg);
  HostImage img(o.width, o.height, 3);
  img.channel_names = {"R", "G", "B"};
  img.channel_formats = {"half", "half", "half"};
  constexpr int kSuper = 4;  // 4x4 sub-texel points: the disc's edge is anti-aliased
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      double acc[3] = {0.0, 0.0, 0.0};
      for (int sy = 0; sy < kSuper; ++sy)
        for (int sx = 0; sx < kSuper; ++sx) {
          const double t = (y + (sy + 0.5) / kSuper) * kPi / o.height;
          const double p = (x + (sx + 0.5) / kSuper) * 2.0 * kPi / o.width;
          const double d[3] = {std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p)};
          double c[3];
          if (d[1] >= 0.0) {  // sky: warm white at the horizon to blue at the zenith
            const double a = std::sqrt(d[1]);
            const double horizon[3] = {1.0, 0.93, 0.85}, zenith[3] = {0.22, 0.42, 0.95};
            for (int k = 0; k < 3; ++k) c[k] = horizon[k] + (zenith[k] - horizon[k]) * a;
          } else {  // ground: dark, a little brighter toward the horizon
            const double g = 0.12 + 0.08 * (1.0 + d[1]);
            c[0] = g;
            c[1] = g * 0.9;
            c[2] = g * 0.75;
          }
          if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] >= cos_radius) {
            c[0] = o.sun_radiance;
            c[1] = o.sun_radiance * 0.93;
            c[2] = o.sun_radiance * 0.8;
          }
          for (int k = 0; k < 3; ++k) acc[k] += c[k];
        }
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = float(acc[k] / (kSuper * kSuper));
    }
  return img;
}

}  // namespace sf::scene

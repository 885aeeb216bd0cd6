// Errors against a reference: the statistics, the metrics by name, and s_ref for the weights a
// configuration approximates.
#include <algorithm>
#include <cmath>
#include <thread>

#include "evaluate.hpp"
#include "lookups.hpp"
#include "receiver_plane.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {

// --- errors ----------------------------------------------------------------------------------------

ErrorStats error_stats(const std::vector<float>& v, const std::vector<double>& ref, const std::vector<uint8_t>& mask) {
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

// Window sums by an integral image: per receiver, how many counted receivers lie in its window
// and how many of them the hard reference lights.
AcneLeak acne_leak(const std::vector<float>& v, const HostImage& ref_hard, const std::vector<uint8_t>& mask,
                   int radius) {
  AcneLeak out;
  const int w = ref_hard.width, h = ref_hard.height;
  const size_t n = ref_hard.texels();
  if (n == 0 || v.size() != n || mask.size() != n || ref_hard.channels != 1) return out;
  out.valid = true;
  const size_t stride = size_t(w) + 1;
  std::vector<uint32_t> counted(stride * (size_t(h) + 1), 0), lit(counted.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const size_t s = (size_t(y) + 1) * stride + x + 1;
      const uint32_t c = mask[i] ? 1u : 0u;
      const uint32_t l = (mask[i] && ref_hard.data[i] >= 0.5f) ? 1u : 0u;
      counted[s] = c + counted[s - 1] + counted[s - stride] - counted[s - stride - 1];
      lit[s] = l + lit[s - 1] + lit[s - stride] - lit[s - stride - 1];
    }
  auto box = [&](const std::vector<uint32_t>& t, int x0, int y0, int x1, int y1) {  // inclusive, clipped
    return t[size_t(y1 + 1) * stride + x1 + 1] - t[size_t(y0) * stride + x1 + 1] - t[size_t(y1 + 1) * stride + x0] +
           t[size_t(y0) * stride + x0];
  };
  size_t acne = 0, leak = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!mask[i]) continue;
      const int x0 = std::max(0, x - radius), x1 = std::min(w - 1, x + radius);
      const int y0 = std::max(0, y - radius), y1 = std::min(h - 1, y + radius);
      const uint32_t c = box(counted, x0, y0, x1, y1), l = box(lit, x0, y0, x1, y1);
      // Written so that a NaN output counts as the error of either class.
      if (l == c) {
        ++out.lit;
        acne += !(v[i] >= 0.5f);
      } else if (l == 0) {
        ++out.shadowed;
        leak += !(v[i] <= 0.5f);
      }
    }
  out.acne = out.lit ? double(acne) / double(out.lit) : 0.0;
  out.leak = out.shadowed ? double(leak) / double(out.shadowed) : 0.0;
  return out;
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

// --- s_ref -----------------------------------------------------------------------------------------

std::vector<double> s_ref_parallel(const HostImage& depth, const BlurOptions& blur, Lookup lookup, const Receivers& rx,
                                   double bias, const ReceiverPlaneOptions& plane, int max_anisotropy) {
  const size_t n = rx.count();
  std::vector<double> out(n, 1.0);
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, n / 4096)));
  auto work = [&](size_t t) {
    for (size_t i = t; i < n; i += threads) {
      const double u = rx.grid ? ref::texel_centre(int(i % rx.width), rx.width) : rx.u[i];
      const double v = rx.grid ? ref::texel_centre(int(i / rx.width), rx.height) : rx.v[i];
      out[i] = ref::s_ref(depth, blur, lookup, u, v, ref::receiver_plane(depth, rx, i, plane),
                          ref::probes_at(rx, i, max_anisotropy), bias);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  return out;
}

const std::vector<double>& SrefCache::get(const BlurOptions& blur, Lookup lookup, int max_anisotropy) {
  const float sigma = blur.radius > 0 ? (blur.sigma > 0 ? blur.sigma : float((2 * blur.radius + 1) / 6.0)) : 0.0f;
  const std::string key = std::to_string(blur.radius) + "/" + std::to_string(sigma) + "/" +
                          std::to_string(int(lookup)) + "/" + std::to_string(max_anisotropy);
  auto it = cache_.find(key);
  if (it != cache_.end()) return it->second;
  return cache_[key] = s_ref_parallel(scene_.depth, blur, lookup, scene_.receivers, bias_, {}, max_anisotropy);
}

const std::vector<double>& SrefCache::for_options(const FilterOptions& o) {
  const MethodDesc& m = *o.method;
  BlurOptions blur = o.blur;
  if (!m.filtered) blur = BlurOptions{};
  return get(blur, m.raw_depth ? Lookup::Bilinear : o.lookup.kind, o.lookup.max_anisotropy);
}

}  // namespace sf::eval

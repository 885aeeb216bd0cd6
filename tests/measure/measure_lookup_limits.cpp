// Lookup limits (docs/numerics.md, "Lookup limits"): every method x storage x lookup with its
// parameters at their limits, on maps whose depth range reaches the limit, against the method's
// double-precision twin on the same stored basis and weights (the error the documented bounds
// cover) and against s_ref (the method's own approximation); and the summed-area table's error
// model (sat_precision.hpp) against the measured error below and beyond the limit it sets.
// Not part of the test suite (minutes):
//   build/tests/sf_measure --gtest_filter='LookupLimits.*' | grep LIMITS
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "lookups.hpp"
#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/depth_range.hpp"
#include "shadowfilter/errors.hpp"
#include "method_cases.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/lookup.hpp"

namespace sf::test {
namespace {

// A map whose finite depths span exactly [lo, hi]. The top-left quadrant lies near hi: the
// largest basis values, in every table entry a bottom-right box subtracts. The rest is 8x8
// blocks: one in four near hi, the others at lo, half of those flat (a box inside sees one depth:
// the moment methods' variance at its floor, where they are most sensitive) and half with noise
// of 1% of the span (contact, penumbrae).
HostImage limit_map(int W, int H, float lo, float hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(0.0f, 0.01f);
  HostImage m(W, H, 1);
  const float span = hi - lo;
  const int bw = (W + 7) / 8;
  std::vector<int> block(size_t(bw) * ((H + 7) / 8));
  for (auto& b : block) b = int(rng() % 8);  // 0, 1: near hi; 2..4: flat at lo; 5..7: lo with noise
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int b = block[size_t(y / 8) * bw + x / 8];
      const bool bright = (x < W / 2 && y < H / 2) || b < 2;
      m.at(x, y) = bright ? hi - span * noise(rng) : b < 5 ? lo : lo + span * noise(rng);
    }
  m.at(0, 0) = hi;
  return m;
}

// n receivers (one row), half of them in the bottom-right quadrant where the table's corners are
// largest; footprints 1 .. 24 texels; each on its texel's depth plus an offset: absolute ones of
// 1e-5 .. 1e-3 (just behind a flat surface, where a Chebyshev bound turns: v_min / 2 for evsm)
// and -2% .. 5% of the span.
Receivers limit_receivers(const HostImage& m, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> all(0.0f, 1.0f), corner(0.5f, 1.0f);
  const float fs[] = {1.0f, 1.5f, 3.0f, 8.0f, 24.0f};
  const MapRange r = depth_range(m);
  const float offsets[] = {
      0.0f, 1e-5f, 3e-5f, 5e-5f, 1e-4f, 3e-4f, 1e-3f, -0.02f * r.span(), 0.01f * r.span(), 0.05f * r.span()};
  const int n_offsets = int(sizeof offsets / sizeof offsets[0]);
  Receivers rx;
  rx.width = n;
  rx.height = 1;
  rx.has_footprint = true;
  for (int i = 0; i < n; ++i) {
    const float u = i % 2 ? corner(rng) : all(rng), v = i % 2 ? corner(rng) : all(rng);
    const int x = std::min(int(u * m.width), m.width - 1), y = std::min(int(v * m.height), m.height - 1);
    rx.u.push_back(u);
    rx.v.push_back(v);
    rx.f.push_back(fs[rng() % 5]);
    rx.d.push_back(std::clamp(m.at(x, y) + offsets[rng() % n_offsets], 0.0f, 1.0f));
  }
  return rx;
}

// The kernels without the pipeline, so without its refusal: transform, table, box lookup and
// reconstruction (radius 0), to measure past the limit.
std::vector<float> sat_unchecked(const FilterOptions& o, const HostImage& m, const Receivers& rx) {
  Runtime& rt = runtime();
  const MethodDesc& method = *o.method;
  const ImageShape shape{m.width, m.height, method.channels(o), storage_bytes(o.storage)};
  cl::Buffer depth = to_device(m.data);
  cl::Buffer basis(rt.context(), CL_MEM_READ_WRITE, shape.bytes());
  enqueue_transform(rt, method, o, m.width, m.height, depth, basis).wait();
  const SatLayout L = sat_layout(shape);
  LookupBuffers lk;
  lk.kind = Lookup::Sat;
  lk.sat = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, L.table_floats * sizeof(float));
  cl::Buffer bands(rt.context(), CL_MEM_READ_WRITE, L.band_floats * sizeof(float));
  enqueue_sat(rt, o.storage, {}, {}, shape, basis, lk.sat, bands).wait();
  lk.footprint = to_device(rx.f);
  const size_t n = rx.count();
  cl::Buffer vis(rt.context(), CL_MEM_READ_WRITE, n * sizeof(float));
  enqueue_reconstruct_points(rt, method, o, m.width, m.height, n, 0, basis, &lk, to_device(rx.u), to_device(rx.v),
                             to_device(rx.d), vis)
      .wait();
  return from_device(vis, n);
}

struct Errors {
  double worst = 0, p99 = 0;
};

Errors errors(const std::vector<float>& got, const std::vector<double>& want) {
  std::vector<double> e(got.size());
  for (size_t i = 0; i < got.size(); ++i) e[i] = std::fabs(double(got[i]) - want[i]);
  std::sort(e.begin(), e.end());
  Errors r;
  if (e.empty()) return r;
  r.worst = e.back();
  r.p99 = e[std::min(e.size() - 1, size_t(0.99 * double(e.size())))];
  return r;
}

// Kernel (through sf::filter) against the twin on the same stored basis and weights.
Errors kernel_vs_twin(const FilterOptions& o, const HostImage& m, const Receivers& rx) {
  return errors(filter(runtime_ptr(), o, m, rx).visibility.data, ref::filter(o, m, rx));
}

// Backward error of a basis method: where its visibility is ill-conditioned (a variance or a
// Hankel determinant at its floor), a few ulps of the looked-up moments move v by up to 1, so
// the twin's forward error says little. The kernel's v passes when it lies within the twin's v
// over perturbations of the looked-up values by up to `ulps` float32 ulps (relative), one storage
// step, and with sat the table's absolute error 4 eps N max|value| (sat_precision.hpp): every
// sign pattern at full size (up to 4 channels) and 64 random ones, widened by 2e-5 (as
// tests/core/test_methods.cpp's msm_backward_ok). Returns the fraction of receivers outside and how
// far the worst lies outside.
struct Backward {
  double outside = 0, worst = 0;
};
Backward backward(const FilterOptions& o, const HostImage& m, const Receivers& rx, const std::vector<float>& got,
                  double ulps) {
  const ref::MethodRef mr = ref::method_ref(o);
  ref::Planes filtered = ref::transform(o, m);
  ref::quantise(filtered, o.storage);
  if (o.blur.radius > 0) {
    filtered = ref::blur(filtered, o.blur.radius, o.blur.sigma);
    ref::quantise(filtered, o.storage);
  }
  const ref::LookupRef lookup(filtered, o.lookup.kind, o.storage);
  double step = o.storage == Storage::Unorm16 ? 1.0 / 65535 : o.storage == Storage::Unorm8 ? 1.0 / 255 : 0.0;
  if (o.lookup.kind == Lookup::Sat) {
    double top = 0;
    for (double x : filtered.data) top = std::max(top, std::fabs(x));
    step += 4.0 * sat_entry_error(runtime().info().fp64) * double(m.texels()) * top;
  }
  const double rel = ulps * std::ldexp(1.0, -24) + (o.storage == Storage::F16 ? std::ldexp(1.0, -11) : 0.0);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> r(-1.0, 1.0);
  Backward b;
  size_t out = 0;
  std::vector<double> v0(mr.channels), v(mr.channels);
  for (size_t i = 0; i < rx.count(); ++i) {
    for (int c = 0; c < mr.channels; ++c) v0[c] = lookup.value(c, rx.u[i], rx.v[i], rx.f[i]);
    const double d = std::clamp(double(rx.d[i]), 0.0, 1.0);
    double lo = mr.visibility(v0.data(), d), hi = lo;
    const int corners = mr.channels <= 4 ? 1 << (2 * mr.channels) : 0;
    for (int k = 0; k < corners + 64; ++k) {
      for (int c = 0; c < mr.channels; ++c) {
        const double a = k < corners ? ((k >> (2 * c)) & 1 ? 1.0 : -1.0) : r(rng);
        const double b = k < corners ? ((k >> (2 * c + 1)) & 1 ? 1.0 : -1.0) : r(rng);
        v[c] = v0[c] * (1 + a * rel) + b * step;
      }
      const double x = mr.visibility(v.data(), d);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    const double dist = std::max({0.0, lo - 2e-5 - got[i], got[i] - hi - 2e-5});
    out += dist > 0;
    b.worst = std::max(b.worst, dist);
  }
  b.outside = rx.count() ? double(out) / double(rx.count()) : 0.0;
  return b;
}

const char* lookup_name(Lookup k) { return k == Lookup::Mips ? "mips" : k == Lookup::Sat ? "sat" : "bilinear"; }

// The summed-area table's model: box means within 4 eps N R of their value (relative). ESM's
// visibility moves by that much: within kSat / 2 e^(c span - L) where L = sat_max_log_ratio(map,
// kSat) is the span limit the registry refuses past (half the budget; the other half is for
// values under the float32 range, which these maps centred on depth 1/2 do not reach). evsm2's limit keeps the second
// moment's box means within 2^-21 (relative), as precise as a float32 lookup: at and below it the table's error should
// not show next to the mip lookup's on the same map. Measured from below the limit to 10^3 beyond it on 128^2 .. 2048^2
// maps, with both accumulators.
TEST(LookupLimits, SatSpanModel) {
  const double kSat = 1e-3, kEvsm = std::ldexp(1.0, -21);
  for (bool fp64 : {true, false}) {
    runtime().set_without_fp64(!fp64);
    for (int size : {128, 512, 2048}) {
      if (!fp64 && size == 2048) continue;
      for (const char* method : {"esm", "evsm2"}) {
        const bool esm = std::string(method) == "esm";
        for (float c : {80.0f, 40.0f, 10.0f}) {
          if (esm != (c == 80.0f)) continue;
          FilterOptions o;
          o.method = method;
          o.esm.c = c;
          o.evsm.pos = c;
          const SatMap map{{0.0f, 0.0f}, size, size, fp64};
          const double rel = esm ? kSat : kEvsm, per_span = esm ? c : 4.0 * c;
          const double L = sat_max_log_ratio(map, rel);
          for (double k : {-4.6, -2.3, 0.0, 2.3, 4.6, 6.9}) {
            const double log_ratio = L + k;
            if (log_ratio <= 0) continue;
            const float span = float(log_ratio / per_span);
            if (span > 1.0f) continue;
            const float lo = 0.5f - span / 2, hi = 0.5f + span / 2;
            const HostImage m = limit_map(size, size, lo, hi, 7);
            const Receivers rx = limit_receivers(m, 4000, 11);
            FilterOptions twin = o;
            twin.lookup.kind = Lookup::Sat;
            const Errors e = errors(sat_unchecked(o, m, rx), ref::filter(twin, m, rx));
            FilterOptions mips = o;
            mips.lookup.kind = Lookup::Mips;
            const Errors base = kernel_vs_twin(mips, m, rx);
            std::printf(
                "LIMITS|model|%s|c=%g|%dx%d|%s|ln R - L = %+.1f|span %.4g|model bound %.2e (%s)|worst %.2e|p99 "
                "%.2e|mips worst %.2e\n",
                method, c, size, size, fp64 ? "double" : "float-float", k, span, rel / 2 * std::exp(k),
                esm ? "visibility" : "relative, 2nd moment", e.worst, e.p99, base.worst);
            std::fflush(stdout);
          }
        }
      }
    }
  }
  runtime().set_without_fp64(false);
}

// One row per method x storage x parameters at the limit x lookup: the worst and p99 of
// |v - twin| and |v - s_ref| over 3000 receivers on a wide map (depths over [0, 1], or the
// widest range the sat limit accepts) and a narrow one (1e-3 wide near 1, where moments cancel).
// Radius 2; the receiver plane off (s_ref of the receiver's own d).
TEST(LookupLimits, EveryCombination) {
  constexpr int kSize = 256;
  struct Variant {
    std::string label;
    FilterOptions options;
  };
  std::vector<Variant> variants;
  for (const MethodCase& mc : method_storage_cases({8, 32})) {
    FilterOptions o = mc.options();
    std::string label = std::string(storage_name(mc.storage));
    if (o.method == "esm") {
      o.esm.c = mc.storage == Storage::F32 ? 174.0f : 22.0f;  // the storage limits
      label += " c=" + std::to_string(int(o.esm.c));
    } else if (o.method == "evsm2" || o.method == "evsm4") {
      o.evsm.pos = o.evsm.neg = mc.storage == Storage::F32 ? 42.0f : 5.54f;
      label += mc.storage == Storage::F32 ? " c+=c-=42" : " c+=c-=5.54";
    } else if (o.method == "csm") {
      label += " M=" + std::to_string(o.csm.order);
    }
    variants.push_back({label, o});
    if (o.method == "esm" && mc.storage == Storage::F32) {  // and the default exponent
      o.esm.c = 80.0f;
      variants.push_back({"f32 c=80", o});
    }
    if (o.method == "evsm4" && mc.storage == Storage::F32) {  // and the default exponents
      o.evsm.pos = 40.0f;
      o.evsm.neg = 5.0f;
      variants.push_back({"f32 c+=40 c-=5", o});
    }
  }
  for (const char* raw : {"sm", "pcf"}) {
    FilterOptions o;
    o.method = raw;
    variants.push_back({"f32", o});
  }
  // SF_LIMITS_METHODS="msm csm" measures only those methods.
  const char* only = std::getenv("SF_LIMITS_METHODS");
  for (const Variant& var : variants) {
    if (only && (" " + std::string(only) + " ").find(" " + var.options.method.name() + " ") == std::string::npos)
      continue;
    for (Lookup kind : {Lookup::Bilinear, Lookup::Mips, Lookup::Sat}) {
      FilterOptions o = var.options;
      o.lookup.kind = kind;
      o.blur.radius = 2;
      o.receiver_plane.enabled = false;
      for (const char* shape : {"wide", "narrow"}) {
        const bool wide = std::string(shape) == "wide";
        float lo = wide ? 0.0f : 0.999f, hi = 1.0f;
        const bool fp64 = runtime().info().fp64;
        std::string note;
        if (kind == Lookup::Sat && !sat_refusal(o, SatMap{{lo, hi}, kSize, kSize, fp64}).empty()) {
          // The widest range the limits accept (a wide map) or the narrow range moved down until
          // they do, over a grid of upper ends.
          const std::string why = sat_refusal(o, SatMap{{lo, hi}, kSize, kSize, fp64});
          float best_lo = 0, best_hi = -1;
          for (int i = 0; i <= 200; ++i) {
            const float top = 1.0f - 0.005f * float(i);
            for (float span = wide ? top : hi - lo; span > 1e-6f; span *= 0.9f) {
              if (!sat_refusal(o, SatMap{{top - span, top}, kSize, kSize, fp64}).empty()) continue;
              if (span > best_hi - best_lo) best_lo = top - span, best_hi = top;
              break;
            }
            if (!wide && best_hi >= 0) break;
          }
          if (best_hi < 0) {
            std::printf("LIMITS|table|%s|%s|%s|%s|refused at every range: %s\n", o.method.name().c_str(),
                        var.label.c_str(), lookup_name(kind), shape, why.c_str());
            continue;
          }
          lo = best_lo;
          hi = best_hi;
          char b[96];
          std::snprintf(b, sizeof b, " (limited to %.4g .. %.4g)", lo, hi);
          note = b;
        }
        const HostImage m = limit_map(kSize, kSize, lo, hi, 3);
        const Receivers rx = limit_receivers(m, 3000, 5);
        const std::vector<float> got = filter(runtime_ptr(), o, m, rx).visibility.data;
        const Errors twin = errors(got, ref::filter(o, m, rx));
        // sm is the unfiltered test: its s_ref has the bilinear weights alone.
        const bool filtered = o.method->filtered;
        const Errors sref =
            errors(got, ref::s_ref(m, filtered ? o.blur : BlurOptions{}, filtered ? kind : Lookup::Bilinear, rx));
        std::string back = "-";
        if (!o.method->raw_depth) {
          const Backward b = backward(o, m, rx, got, 4.0);
          char t[96];
          std::snprintf(t, sizeof t, "outside %.2f%% by <= %.2e", 100.0 * b.outside, b.worst);
          back = t;
        }
        std::printf("LIMITS|table|%s|%s|%s|%s%s|twin worst %.2e p99 %.2e|backward %s|s_ref worst %.3f p99 %.3f\n",
                    o.method.name().c_str(), var.label.c_str(), lookup_name(kind), shape, note.c_str(), twin.worst,
                    twin.p99, back.c_str(), sref.worst, sref.p99);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace
}  // namespace sf::test

// VSM and EVSM (kernels/methods/vsm.clh, evsm.clh): moments (z, z^2), or of exp-warped depths,
// and the one-sided Chebyshev bound with light-bleeding reduction.
#include <algorithm>
#include <cmath>

#include "registration.hpp"

namespace sf::registration {
namespace {

// EVSM stores exp(2 c w), w in [-1,1]: finite when 2c <= ln(max). float32: ln(3.4e38) = 88.7,
// c <= 44.3, and 42 leaves room for the Chebyshev sums; float16: ln(65504) / 2 = 5.54.
constexpr float kEvsmMaxFloat32 = 42.0f;
constexpr float kEvsmMaxFloat16 = 5.54f;
// The relative error a float32 lookup leaves in a moment (a few ulps: 2^-21), which the
// summed-area table may not exceed (docs/numerics.md, "Lookup limits").
constexpr double kSatRelativeError = 1.0 / (1 << 21);

float evsm_limit(Storage s) { return s == Storage::F16 ? kEvsmMaxFloat16 : kEvsmMaxFloat32; }

// Measured defaults (docs/results.md, "Defaults sweep": the lowest worst RMSE against the
// ray-traced soft shadows over the built-in scenes and a scanned mesh at 512 and 2048 maps, radius
// 2). vsm: the variance floor only has to hold a stored mean's rounding, 1e-6 in float32 and 2e-5
// in the 16-bit storages (a flat receiver stays lit when its mean is rounded by half a float16
// ulp). evsm: the warps that keep the Chebyshev bound's penumbrae closest to the soft references,
// with a relative floor of 1e-3 in float32 and 2e-3 in float16; evsm4's negative warp stays at 5,
// where a plane tilted 80 degrees to the light stays lit (c- = 20 fit the scenes better but
// darkened such a plane by 4%: the concave warp reads a tilted support as partly in front).
constexpr float kVsmMinVarianceF32 = 1e-6f, kVsmMinVariance16 = 2e-5f;
constexpr float kEvsm2Pos = 5.0f, kEvsm4Pos = 10.0f, kEvsm4Neg = 5.0f;
constexpr float kEvsmMinVarianceF32 = 1e-3f, kEvsmMinVarianceF16 = 2e-3f;

float evsm_pos(const FilterOptions& o) {
  return o.evsm.pos > 0 ? o.evsm.pos : o.method == "evsm4" ? kEvsm4Pos : kEvsm2Pos;
}
float evsm_neg(const FilterOptions& o) { return o.evsm.neg > 0 ? o.evsm.neg : kEvsm4Neg; }

double chebyshev(double mu, double m2, double t, double vmin) {
  if (t <= mu) return 1.0;
  const double var = std::max(m2 - mu * mu, vmin);
  return var / (var + (t - mu) * (t - mu));
}

double reduce_bleeding(double p, double a) { return std::clamp((p - a) / (1.0 - a), 0.0, 1.0); }

void validate_vsm_common(const FilterOptions& o) {
  require_finite(o.vsm.min_variance, "FilterOptions::vsm.min_variance");
  if (o.vsm.min_variance == 0.0f)
    throw InputError("FilterOptions::vsm.min_variance must be positive (negative = the default)");
  if (!(o.vsm.lbr >= 0.0f && o.vsm.lbr < 1.0f))
    throw InputError("FilterOptions::vsm.lbr must be in [0, 1), got " + num(o.vsm.lbr));
}

sf_vsm_params vsm_params(const FilterOptions& o) {
  return {o.vsm.min_variance > 0 ? o.vsm.min_variance
                                 : (o.storage == Storage::F32 ? kVsmMinVarianceF32 : kVsmMinVariance16),
          o.vsm.lbr};
}

sf_evsm_params evsm_params(const FilterOptions& o) {
  const float limit = evsm_limit(o.storage);
  const float vmin = o.vsm.min_variance > 0 ? o.vsm.min_variance
                                            : (o.storage == Storage::F16 ? kEvsmMinVarianceF16 : kEvsmMinVarianceF32);
  return {std::min(evsm_pos(o), limit), std::min(evsm_neg(o), limit), vmin, o.vsm.lbr};
}

std::string lbr_label(const FilterOptions& o) { return o.vsm.lbr > 0 ? " lbr=" + num(o.vsm.lbr) : ""; }

}  // namespace

MethodDesc vsm_method() {
  MethodDesc m;
  m.name = "vsm";
  m.summary = "variance shadow maps: B = (z, z^2), one-sided Chebyshev bound";
  m.header = "methods/vsm.clh";
  m.channel_count = [](const FilterOptions&) { return 2; };
  m.parameters = "--vsm-min-variance V (default 1e-6 f32, 2e-5 f16 and unorm16), --lbr A (default 0)";
  m.storages = plain_storages({Storage::F32, Storage::F16, Storage::Unorm16});
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o, "8-bit steps of z^2 (1/255) are larger than the variances it needs");
    validate_vsm_common(o);
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(vsm_params(o)); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.scalar = [](const FilterOptions& o) {
    const sf_vsm_params p = vsm_params(o);
    const double vmin = p.min_variance, lbr = p.lbr;
    ScalarMethod s;
    s.channels = 2;
    s.basis = [](double z, double* b) {
      b[0] = z;
      b[1] = z * z;
    };
    s.visibility = [vmin, lbr](const double* b, double d) {
      return reduce_bleeding(chebyshev(b[0], b[1], d, vmin), lbr);
    };
    return s;
  };
  m.parameter_values = [](const FilterOptions& o) {
    return std::vector<MethodParameter>{{"lbr", o.vsm.lbr}, {"min_variance", vsm_params(o).min_variance}};
  };
  m.label = lbr_label;
  m.variants = [](const FilterOptions& base, GridSize g) {
    const std::vector<float> a =
        g == GridSize::Quick ? std::vector<float>{0.0f, 0.2f} : std::vector<float>{0.0f, 0.2f, 0.4f};
    return variants_of(base, a, [](FilterOptions& o, float v) { o.vsm.lbr = v; });
  };
  m.colour = {0.1f, 0.35f, 0.9f};
  return m;
}

MethodDesc evsm_method(int channels) {
  const bool four = channels == 4;
  MethodDesc m;
  m.name = four ? "evsm4" : "evsm2";
  m.summary = four ? "exponential variance shadow maps, positive and negative warps"
                   : "exponential variance shadow maps, positive warp only";
  m.header = "methods/evsm.clh";
  m.channel_count = [channels](const FilterOptions&) { return channels; };
  m.parameters = std::string("--evsm-pos C+ (default ") + (four ? "10), --evsm-neg C- (default 5" : "5") +
                 "; clamped to 42 in f32, 5.54 in f16), --vsm-min-variance V (default 1e-3 f32, "
                 "2e-3 f16), --lbr A (default 0)";
  m.storages = {{Storage::F32, "warps clamped to 42", {}}, {Storage::F16, "warps clamped to 5.54", {}}};
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o, "exp(c w) spans e^-c..e^c, which unorm cannot resolve");
    validate_vsm_common(o);
    if (o.evsm.pos == 0.0f || !std::isfinite(o.evsm.pos) || o.evsm.neg == 0.0f || !std::isfinite(o.evsm.neg))
      throw InputError(
          "FilterOptions::evsm.pos and FilterOptions::evsm.neg must be positive numbers (negative = the default)");
  };
  // The Chebyshev bound amplifies relative errors of the moments by up to 1 / (v_min c)^2 (the
  // variance floor, relative to t^2): float32 lookups already carry a few ulps, and that is what
  // evsm's error bound covers (docs/numerics.md). The table may add no more: box means within
  // kSatRelativeError. With w = 2z - 1 over [wmin, wmax], the positive moments exp(c w), exp(2 c w)
  // and the negative ones' magnitudes exp(-c w), exp(-2 c w).
  m.sat_limit = [four](const FilterOptions& o, const SatMap& map) {
    const sf_evsm_params p = evsm_params(o);
    const double wmin = 2.0 * map.range.min - 1.0, wmax = 2.0 * map.range.max - 1.0;
    auto positive = [=](double c) { return std::vector<LogRange>{{c * wmin, c * wmax}, {2 * c * wmin, 2 * c * wmax}}; };
    auto negative = [=](double c) {
      return std::vector<LogRange>{{-c * wmax, -c * wmin}, {-2 * c * wmax, -2 * c * wmin}};
    };
    const std::string name = four ? "evsm4" : "evsm2", keeps = "the precision of float32 lookups";
    std::string why =
        sat_exponential_refusal(name, "FilterOptions::evsm.pos", p.pos, positive, map, kSatRelativeError, keeps);
    if (why.empty() && four)
      why = sat_exponential_refusal(name, "FilterOptions::evsm.neg", p.neg, negative, map, kSatRelativeError, keeps);
    return why;
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(evsm_params(o)); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.scalar = [four](const FilterOptions& o) {
    const sf_evsm_params p = evsm_params(o);
    const double pos = p.pos, neg = p.neg, vmin = p.min_variance, lbr = p.lbr;
    ScalarMethod s;
    s.channels = four ? 4 : 2;
    s.basis = [=](double z, double* b) {
      const double w = 2 * z - 1;
      b[0] = std::exp(pos * w);
      b[1] = std::exp(2 * pos * w);
      if (four) {
        b[2] = -std::exp(-neg * w);
        b[3] = std::exp(-2 * neg * w);
      }
    };
    s.visibility = [=](const double* b, double d) {
      const double w = 2 * d - 1;
      auto side = [vmin](double m1, double m2, double t, double c) {
        const double sd = vmin * c * std::fabs(t);
        return chebyshev(m1, m2, t, sd * sd);
      };
      double v = side(b[0], b[1], std::exp(pos * w), pos);
      if (four) v = std::min(v, side(b[2], b[3], -std::exp(-neg * w), neg));
      return reduce_bleeding(v, lbr);
    };
    return s;
  };
  m.parameter_values = [four](const FilterOptions& o) {
    std::vector<MethodParameter> p{{"lbr", o.vsm.lbr}, {"c+", evsm_pos(o)}};
    if (four) p.push_back({"c-", evsm_neg(o)});
    p.push_back({"min_variance", evsm_params(o).min_variance});
    return p;
  };
  m.label = [](const FilterOptions& o) { return lbr_label(o) + " c+=" + num(evsm_pos(o)); };
  m.variants = [](const FilterOptions& base, GridSize g) {
    if (g != GridSize::Wide && g != GridSize::Auto) return std::vector<FilterOptions>{base};
    return variants_of(base, std::vector<float>{20.0f, 40.0f}, [](FilterOptions& o, float c) { o.evsm.pos = c; });
  };
  m.cost.reconstruct = four ? 40.0 : 9.0;  // two Chebyshev bounds / one
  m.colour = four ? std::array<float, 3>{0.1f, 0.6f, 0.1f} : std::array<float, 3>{0.0f, 0.65f, 0.65f};
  return m;
}

}  // namespace sf::registration

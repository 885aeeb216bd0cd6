// VSM and EVSM (kernels/methods/vsm.clh, evsm.clh): moments (z, z^2), or of exp-warped depths,
// and the one-sided Chebyshev bound with light-bleeding reduction.
#include <algorithm>
#include <cmath>
#include <limits>

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

float evsm_pos(const FilterOptions& o, bool four) { return o.evsm.pos > 0 ? o.evsm.pos : four ? kEvsm4Pos : kEvsm2Pos; }
float evsm_neg(const FilterOptions& o) { return o.evsm.neg > 0 ? o.evsm.neg : kEvsm4Neg; }

double chebyshev(double mu, double m2, double t, double vmin) {
  if (t <= mu) return 1.0;
  const double var = std::max(m2 - mu * mu, vmin);
  return var / (var + (t - mu) * (t - mu));
}

double reduce_bleeding(double p, double a) { return std::clamp((p - a) / (1.0 - a), 0.0, 1.0); }

constexpr double kInf = std::numeric_limits<double>::infinity();

// The parameters vsm, evsm2 and evsm4 share, and evsm's warps: each declared once here.
Parameter min_variance_parameter() {
  return Parameter::real("FilterOptions::vsm.min_variance", "--vsm-min-variance", "V",
                         "Minimum variance (vsm: absolute floor of bar(z^2) - bar(z)^2; evsm: relative, the floor per "
                         "side is (V c |warped d|)^2)")
      .resolved_by_method("vsm " + num(kVsmMinVarianceF32) + " in f32, " + num(kVsmMinVariance16) +
                          " in f16 and unorm16; evsm " + num(kEvsmMinVarianceF32) + " in f32, " +
                          num(kEvsmMinVarianceF16) + " in f16")
      .within({0, kInf, true})
      .unset_when(ParameterUnset::Negative)
      .on(&FilterOptions::vsm, &VsmOptions::min_variance);
}

Parameter lbr_parameter() {
  return Parameter::real("FilterOptions::vsm.lbr", "--lbr", "A",
                         "Light-bleeding reduction a: v = clamp((p - a) / (1 - a), 0, 1)")
      .with_default(VsmOptions{}.lbr)
      .within({0, 1, false, true})
      .on(&FilterOptions::vsm, &VsmOptions::lbr);
}

Parameter evsm_pos_parameter() {
  return Parameter::real("FilterOptions::evsm.pos", "--evsm-pos", "C+",
                         "EVSM positive warp exponent (clamped to the storage's limit: " + num(kEvsmMaxFloat32) +
                             " in f32, " + num(kEvsmMaxFloat16) + " in f16)")
      .resolved_by_method("evsm2 " + num(kEvsm2Pos) + ", evsm4 " + num(kEvsm4Pos))
      .within({0, kInf, true})
      .unset_when(ParameterUnset::Negative)
      .on(&FilterOptions::evsm, &EvsmOptions::pos);
}

Parameter evsm_neg_parameter() {
  return Parameter::real("FilterOptions::evsm.neg", "--evsm-neg", "C-",
                         "EVSM negative warp exponent (clamped to the storage's limit: " + num(kEvsmMaxFloat32) +
                             " in f32, " + num(kEvsmMaxFloat16) + " in f16)")
      .resolved_by_method(num(kEvsm4Neg))
      .within({0, kInf, true})
      .unset_when(ParameterUnset::Negative)
      .on(&FilterOptions::evsm, &EvsmOptions::neg);
}

sf_vsm_params vsm_params(const FilterOptions& o) {
  return {o.vsm.min_variance > 0 ? o.vsm.min_variance
                                 : (o.storage == Storage::F32 ? kVsmMinVarianceF32 : kVsmMinVariance16),
          o.vsm.lbr};
}

sf_evsm_params evsm_params(const FilterOptions& o, bool four) {
  const float limit = evsm_limit(o.storage);
  const float vmin = o.vsm.min_variance > 0 ? o.vsm.min_variance
                                            : (o.storage == Storage::F16 ? kEvsmMinVarianceF16 : kEvsmMinVarianceF32);
  return {std::min(evsm_pos(o, four), limit), std::min(evsm_neg(o), limit), vmin, o.vsm.lbr};
}

}  // namespace

MethodDesc vsm_method() {
  MethodDesc m;
  m.name = "vsm";
  m.summary = "variance shadow maps: B = (z, z^2), one-sided Chebyshev bound";
  m.header = "methods/vsm.clh";
  m.channel_count = [](const FilterOptions&) { return 2; };
  m.parameters = {min_variance_parameter(), lbr_parameter()};
  m.storages = plain_storages({Storage::F32, Storage::F16, Storage::Unorm16});
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o, "8-bit steps of z^2 (1/255) are larger than the variances it needs");
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
  m.parameters = {evsm_pos_parameter(), min_variance_parameter(), lbr_parameter()};
  if (four) m.parameters.insert(m.parameters.begin() + 1, evsm_neg_parameter());
  m.storages = {{Storage::F32, "warps clamped to 42", {}}, {Storage::F16, "warps clamped to 5.54", {}}};
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o, "exp(c w) spans e^-c..e^c, which unorm cannot resolve");
  };
  // The Chebyshev bound amplifies relative errors of the moments by up to 1 / (v_min c)^2 (the
  // variance floor, relative to t^2): float32 lookups already carry a few ulps, and that is what
  // evsm's error bound covers (docs/numerics.md). The table may add no more: box means within
  // kSatRelativeError. With w = 2z - 1 over [wmin, wmax], the positive moments exp(c w), exp(2 c w)
  // and the negative ones' magnitudes exp(-c w), exp(-2 c w).
  m.sat_limit = [four](const FilterOptions& o, const SatMap& map) {
    const sf_evsm_params p = evsm_params(o, four);
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
  m.pack_params = [four](const FilterOptions& o) { return bytes_of(evsm_params(o, four)); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.scalar = [four](const FilterOptions& o) {
    const sf_evsm_params p = evsm_params(o, four);
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
    std::vector<MethodParameter> p{{"lbr", o.vsm.lbr}, {"c+", evsm_pos(o, four)}};
    if (four) p.push_back({"c-", evsm_neg(o)});
    p.push_back({"min_variance", evsm_params(o, four).min_variance});
    return p;
  };
  return m;
}

}  // namespace sf::registration

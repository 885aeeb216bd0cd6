// MSM (kernels/methods/msm.clh): four moments, Hamburger or Hausdorff reconstruction
// (Peters & Klein 2015); unorm16 stores the optimised quantisation of the moments.
#include <algorithm>
#include <cmath>

#include "registration.hpp"

namespace sf::registration {
namespace {

// Peters & Klein 2015, optimised moment quantisation: b' = B Q + (0.0359558848, 0, 0, 0) with
// B the row (z, z^2, z^3, z^4), and its inverse.
constexpr double kQ[4][4] = {{-2.07224649, 13.7948857237, 0.105877704, 9.7924062118},
                             {32.23703778, -59.4683975703, -1.9077466311, -33.7652110555},
                             {-68.571074599, 82.0359750338, 9.3496555107, 47.9456096605},
                             {39.3703274134, -35.364903257, -6.6543490743, -23.9728048165}};
constexpr double kQinv[4][4] = {{0.2227744146, 0.1549679261, 0.1451988946, 0.163127443},
                                {0.0771972861, 0.1394629426, 0.2120202157, 0.2591432266},
                                {0.7926986636, 0.7963415838, 0.7258694464, 0.6539092497},
                                {0.0319417555, -0.1722823173, -0.2758014811, -0.3376131734}};
constexpr double kQoffset = 0.035955884801;

void optimised_moments(double z, double* out) {
  const double m[4] = {z, z * z, z * z * z, z * z * z * z};
  for (int j = 0; j < 4; ++j) {
    out[j] = 0;
    for (int i = 0; i < 4; ++i) out[j] += m[i] * kQ[i][j];
  }
  out[0] += kQoffset;
}

void power_moments(const double* q, double* out) {
  const double x[4] = {q[0] - kQoffset, q[1], q[2], q[3]};
  for (int j = 0; j < 4; ++j) {
    out[j] = 0;
    for (int i = 0; i < 4; ++i) out[j] += x[i] * kQinv[i][j];
  }
}

// G for a support of at most two points (a singular Hankel matrix: the moment bias cannot lift
// it when the support is {0, 1}, because the bias vector (1/2, ...) is itself such a support).
// The atoms z_a < z_b have z_a + z_b = (b3 - b1 b2) / D22 and z_a z_b = (b1 b3 - b2^2) / D22.
double two_atoms(double b1, double b2, double b3, double d) {
  const double D22 = b2 - b1 * b1;
  if (!(D22 > 0)) return d > b1 ? 1.0 : 0.0;  // one atom at b1
  const double s = (b3 - b1 * b2) / D22, p = (b1 * b3 - b2 * b2) / D22;
  const double r = std::sqrt(std::max(s * s / 4 - p, 0.0));
  const double za = s / 2 - r, zb = s / 2 + r;
  if (!(zb > za)) return d > b1 ? 1.0 : 0.0;
  const double wb = std::clamp((b1 - za) / (zb - za), 0.0, 1.0);
  return (d > za ? 1 - wb : 0.0) + (d > zb ? wb : 0.0);
}

// G, the shadow intensity, from power moments (methods.md sec. 3), in double. The Cholesky
// factorisation is written as L D L^T with the products Peters & Klein keep; the kernel
// evaluates the same expressions (in double where the device has fp64).
double intensity(const double* m, double d, double a, bool hausdorff) {
  const double b1 = (1 - a) * m[0] + a * 0.5, b2 = (1 - a) * m[1] + a * 0.5;
  const double b3 = (1 - a) * m[2] + a * 0.5, b4 = (1 - a) * m[3] + a * 0.5;
  const double D22 = b2 - b1 * b1;
  const double L32D22 = b3 - b1 * b2;
  const double var2 = b4 - b2 * b2;
  const double D33D22 = var2 * D22 - L32D22 * L32D22;
  if (!(D22 > 0) || !(D33D22 > 0)) return two_atoms(b1, b2, b3, d);
  const double L32 = L32D22 / D22;
  // Solve L D L^T c = (1, d, d^2): forward substitution, scaling, backward substitution.
  double c1 = 1, c2 = d - b1, c3 = d * d - b2 - L32 * (d - b1);
  c2 /= D22;
  c3 *= D22 / D33D22;
  c2 -= L32 * c3;
  c1 -= c2 * b1 + c3 * b2;
  const double p = c2 / c3, q = c1 / c3;
  const double r = std::sqrt(std::max(p * p / 4 - q, 0.0));
  const double z2 = -p / 2 - r, z3 = -p / 2 + r;
  double G;
  if (d <= z2) {
    G = 0;
  } else if (d <= z3) {
    G = (d * z3 - b1 * (d + z3) + b2) / ((z3 - z2) * (d - z2));
  } else {
    G = 1 - (z2 * z3 - b1 * (z2 + z3) + b2) / ((d - z2) * (d - z3));
  }
  if (hausdorff && (z2 < 0 || z3 > 1)) {
    const double zf = ((b3 - b2) * d + b3 - b4) / ((b2 - b1) * d + b2 - b3);
    const double w1 = d > zf ? 1.0 : 0.0;
    const double G4 =
        (b2 - b1 + (b3 - b1 - (zf + 1) * (b2 - b1)) * (zf - w1 - d) / (d * (d - zf))) / (zf - w1) + 1 - b1;
    if (std::isfinite(G4)) G = G4;
  }
  if (!std::isfinite(G)) G = two_atoms(b1, b2, b3, d);
  return G;
}

// msm in unorm16: the smallest depth bias that keeps every flat receiver lit (test MsmUnormBias;
// the measurement is in docs/methods.md) with a 10x margin, below where Hausdorff's [0,1] support
// starts to cut off receivers near z = 0.
constexpr float kUnorm16DepthBias = 1e-4f;

// Measured float32 defaults (docs/results.md "Defaults sweep": the lowest worst RMSE against the
// ray-traced soft shadows over the built-in scenes and a scanned mesh at 512 and 2048 maps): a
// moment bias of 1e-4 (3e-6 darkened tilted planes, 3% at 80 degrees), and for the Hausdorff
// bound 1e-3 with a depth bias of 3e-4.
constexpr float kMomentBiasF32 = 1e-4f;
constexpr float kHausdorffMomentBiasF32 = 1e-3f;
constexpr float kHausdorffDepthBiasF32 = 3e-4f;

// Peters & Klein 2015's moment bias for the optimised 16-bit quantisation.
constexpr float kMomentBiasUnorm16 = 6e-5f;

float moment_bias(const FilterOptions& o, bool hausdorff) {
  if (o.msm.moment_bias >= 0) return o.msm.moment_bias;
  if (o.storage != Storage::F32) return kMomentBiasUnorm16;
  return hausdorff ? kHausdorffMomentBiasF32 : kMomentBiasF32;
}

// msm's and msm-hausdorff's one parameter, declared once.
Parameter moment_bias_parameter() {
  return Parameter::real("FilterOptions::msm.moment_bias", "--msm-bias", "A",
                         "MSM moment bias a: b = (1 - a) bar(B) + a (1/2, ...)")
      .resolved_by_method("msm " + num(kMomentBiasF32) + ", msm-hausdorff " + num(kHausdorffMomentBiasF32) +
                          " in f32; " + num(kMomentBiasUnorm16) + " in unorm16")
      .within({0, 1})
      .unset_when(ParameterUnset::Negative)
      .on(&FilterOptions::msm, &MsmOptions::moment_bias);
}

}  // namespace

MethodDesc msm_method(bool hausdorff) {
  MethodDesc m;
  m.name = hausdorff ? "msm-hausdorff" : "msm";
  // Half a texel along the normal (docs/results.md "Normal offset"): terrain's umbra leak 11.1% ->
  // 5.9% at 512, acne and RMSE as before. msm-hausdorff none (its mean RMSE +5%, leaks elsewhere
  // 0.37 -> 0.69%).
  m.default_normal_offset = hausdorff ? 0.0f : 0.5f;
  m.summary = hausdorff ? "moment shadow maps, 4 moments, Hausdorff (bounded support [0,1])"
                        : "moment shadow maps, 4 moments, Hamburger (Peters & Klein 2015)";
  m.header = "methods/msm.clh";
  m.channel_count = [](const FilterOptions&) { return 4; };
  m.parameters = {moment_bias_parameter()};
  m.reads = {"FilterOptions::depth_test.bias"};
  m.storages = {{Storage::F32, "", {}}, {Storage::Unorm16, "optimised moment quantisation", {}}};
  m.validate = [m](const FilterOptions& o) {
    check_storage(m, o,
                  "16 bits need the optimised quantisation, which unorm16 resolves 32x finer than "
                  "f16 on [0,1]; 8 bits are far too coarse for 4 moments");
    require_finite(o.msm.moment_bias, "FilterOptions::msm.moment_bias");
    require_finite(depth_bias(o), "FilterOptions::depth_test.bias");
  };
  m.default_depth_bias = [hausdorff](const FilterOptions& o) {
    if (o.storage == Storage::Unorm16) return kUnorm16DepthBias;
    return hausdorff ? kHausdorffDepthBiasF32 : 0.0f;
  };
  m.pack_params = [hausdorff](const FilterOptions& o) {
    return bytes_of(sf_msm_params{moment_bias(o, hausdorff), depth_bias(o)});
  };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.scalar = [hausdorff](const FilterOptions& o) {
    const double a = moment_bias(o, hausdorff), bias = depth_bias(o);
    const bool optimised = storage_unorm(o.storage);
    ScalarMethod s;
    s.channels = 4;
    s.basis = [optimised](double z, double* b) {
      if (optimised) {
        optimised_moments(z, b);
      } else {
        b[0] = z;
        b[1] = z * z;
        b[2] = z * z * z;
        b[3] = z * z * z * z;
      }
    };
    s.visibility = [=](const double* b, double d) {
      double pm[4];
      if (optimised) {
        power_moments(b, pm);
      } else {
        std::copy(b, b + 4, pm);
      }
      return std::clamp(1 - intensity(pm, d - bias, a, hausdorff), 0.0, 1.0);
    };
    return s;
  };
  m.parameter_values = [hausdorff](const FilterOptions& o) {
    return std::vector<MethodParameter>{{"bias", depth_bias(o)}, {"moment_bias", moment_bias(o, hausdorff)}};
  };
  return m;
}

}  // namespace sf::registration

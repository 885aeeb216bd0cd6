#pragma once
// The scalar reference: plain double-precision loops over the same math as the kernels
// (methods.md). Deliberately straightforward; tests compare every kernel against it.
#include <functional>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"

namespace sf::ref {

// A planar double image: channel c texel (x, y) at data[c * width * height + y * width + x].
struct Planes {
  int width = 0, height = 0, channels = 1;
  std::vector<double> data;
  Planes() = default;
  Planes(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, 0.0) {}
  double& at(int c, int x, int y) { return data[(size_t(c) * height + y) * width + x]; }
  double at(int c, int x, int y) const { return data[(size_t(c) * height + y) * width + x]; }
};

// --- every basis method ------------------------------------------------------
// The method's double-precision twin (MethodDesc::scalar, registered beside its kernel header)
// with the parameters the registry resolves (defaults, clamps) for `opt`, after the registry
// validated them: basis values as the kernel stores them before rounding, and the visibility
// from filtered stored values, clamped to [0,1].
using MethodRef = ScalarMethod;
MethodRef method_ref(const FilterOptions& opt);  // basis methods (not sm, pcf)
// The basis planes of a depth map (unrounded).
Planes transform(const FilterOptions& opt, const HostImage& depth);
// The value a basis value reads back as after sf_store / sf_load in storage s (f16: round to
// nearest even; unorm: round(v * max) / max with v clamped to [0,1]).
double quantise(double v, Storage s);
void quantise(Planes& p, Storage s);

// sm and pcf (methods_pcf.cpp): sum_t W_x(t) H(z_t - d + bias) under the composite weights of
// `blur` (sm: pass radius 0), brute force. Background / outside = 1. bias 0 gives s_ref.
double pcf(const HostImage& depth, const BlurOptions& blur, double u, double v, double d, double bias);
// The same against a receiver's plane (receiver_plane.hpp): H(z_t - plane(t) + bias).
struct Plane;
double pcf(const HostImage& depth, const BlurOptions& blur, const Plane& plane, double bias);

// --- filters and lookups -----------------------------------------------------
std::vector<double> gaussian_weights(int radius, double sigma);  // w[0..R]; sigma <= 0: default
Planes blur(const Planes& in, int radius, double sigma);         // rows then columns, clamped
// Bilinear, clamp-to-edge, texel centres at (i + 0.5) / W.
double bilinear(const Planes& img, int channel, double u, double v);

// --- full pipeline -----------------------------------------------------------
// Visibility per receiver (background / outside = 1), exactly as the kernels define it.
std::vector<double> filter(const FilterOptions& opt, const HostImage& depth, const Receivers& rx);

// --- the exact filtered shadow test s_ref (methods.md sec. 2) -----------------
// sum_t W_x(t) H(z_t - d) with the composite Gaussian (x) bilinear weights of `blur`
// (radius 0 = bilinear only), brute force over the texels. Background / outside = 1.
double s_ref(const HostImage& depth, const BlurOptions& blur, double u, double v, double d);
std::vector<double> s_ref(const HostImage& depth, const BlurOptions& blur, const Receivers& rx);

// Texture coordinate of a grid receiver (texel centre).
inline double texel_centre(int i, int n) { return (i + 0.5) / n; }

}  // namespace sf::ref

#pragma once
// Scalar double-precision reference of pyramids, summed-area tables and footprint lookups
// (methods.md sec. 2; docs/lookups.md), and the exact filtered test s_ref under them.
#include <vector>

#include "reference.hpp"
#include "shadowfilter/footprint.hpp"

namespace sf::ref {

// Reduction of a pyramid: 0 = mean 0.25 ((a + b) + (c + d)), 1 = max, 2 = min.
// Level k+1 texel (i, j) reduces level-k texels (2i..2i+1, 2j..2j+1) clamped to level k.
std::vector<Planes> mip_chain(const Planes& level0, int op);

// Summed-area table: (W+1) x (H+1) per channel, S(x, y) = sum of texels [0,x) x [0,y).
Planes sat_table(const Planes& img);

// Footprint of receiver i: rx.f[i] when the receivers carry one, else 1.
double footprint_at(const Receivers& rx, size_t i);

// The probes of receiver i's footprint lookup (footprint.hpp): its Jacobian's where the receivers
// carry one and max_anisotropy > 1, else one probe of footprint footprint_at(rx, i).
FootprintProbes probes_at(const Receivers& rx, size_t i, int max_anisotropy);
// One probe of footprint f (fx = fy = f).
FootprintProbes isotropic_probe(double f);
// Probe k's coordinates, rounded as the kernels compute them: u + (offset du) / W in float.
void probe_uv(const FootprintProbes& p, int k, int W, int H, double u, double v, double& uk, double& vk);

// Level of detail as the kernels compute it: k0 = floor(log2(max(f,1))) (float32 log2),
// t = fraction, clamped to the top level.
int lod(double f, int top, double& t);

// Trilinear lookup of channel c of a chain at (u, v) with footprint f.
double trilinear(const std::vector<Planes>& chain, int c, double u, double v, double f);
// Area-weighted mean over the square of side max(f,1) centred at (u, v), clamp-to-edge, brute
// force over texels (corners rounded to float32 like the kernel: fma(u, W, -+side/2)).
double box_mean(const Planes& img, int c, double u, double v, double f);
// The same over fx x fy texels (each at least 1).
double box_mean(const Planes& img, int c, double u, double v, double fx, double fy);

// A filtered basis read through a lookup (mip chain built once).
class LookupRef {
 public:
  LookupRef(const Planes& filtered, Lookup kind, Storage storage = Storage::F32);
  // The same with a storage per plane (plane_storage[c] for plane c, one per channel): each mip
  // level's plane c is rounded as a pyramid stored in plane_storage[c] holds it.
  LookupRef(const Planes& filtered, Lookup kind, const std::vector<Storage>& plane_storage);
  double value(int c, double u, double v, double f) const;
  // The mean of the probes' lookups (mips at p.f, the box over p.fx x p.fy).
  double value(int c, double u, double v, const FootprintProbes& p) const;
  // Area-weighted mean over fx x fy texels of level 0 (box_mean; a rectangle through a SAT).
  double box(int c, double u, double v, double fx, double fy) const;

 private:
  Lookup kind_;
  std::vector<Planes> chain_;
};

// Composite weights on the depth texels of a lookup: Gaussian prefilter (blur) applied before
// bilinear / trilinear / box at (u, v) with footprint f (methods.md sec. 2). Every texel with a
// non-zero weight is listed once; the weights sum to 1.
struct Tap {
  int x, y;
  double w;
};
std::vector<Tap> lookup_taps(int width, int height, const BlurOptions& blur, Lookup kind, double u, double v, double f);
// The same for the mean of a footprint's probes (each weighted 1 / p.n).
std::vector<Tap> lookup_taps(int width, int height, const BlurOptions& blur, Lookup kind, double u, double v,
                             const FootprintProbes& p);

// s_ref under a lookup: sum_t W_x(t) H(z_t - d + bias). Background / outside = 1.
double s_ref(const HostImage& depth, const BlurOptions& blur, Lookup kind, double u, double v, double d, double f,
             double bias = 0.0);
// The same against a receiver's plane (receiver_plane.hpp): sum_t W_x(t) H(z_t - plane(t) + bias).
struct Plane;
double s_ref(const HostImage& depth, const BlurOptions& blur, Lookup kind, double u, double v, const Plane& plane,
             double f, double bias = 0.0);
double s_ref(const HostImage& depth, const BlurOptions& blur, Lookup kind, double u, double v, const Plane& plane,
             const FootprintProbes& probes, double bias = 0.0);
std::vector<double> s_ref(const HostImage& depth, const BlurOptions& blur, Lookup kind, const Receivers& rx);

}  // namespace sf::ref

#pragma once
// Scalar double-precision reference of the soft-shadow methods (kernels/soft/*.cl; docs/soft.md):
// the same decisions and formulas, evaluated in double.
#include "receiver_plane.hpp"
#include "reference.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::ref {

// Area-weighted box (clamp-to-edge) of wx x wy texels centred at (u, v) on a plane: lit = fraction with z >= d_t -
// bias, d_t the receiver's plane `p` (in this image's texel coordinates) at the texel read; blk = fraction with z < d_t
// - bias, blkz = their weighted mean depth (NaN without blockers).
struct BoxScan {
  double lit = 0, blk = 0, zavg = 0;
};
BoxScan box_scan(const double* img, int w, int h, double u, double v, double wx, double wy, const Plane& p,
                 double bias);
// The plane of a level of w x h texels over a W x H map whose texels are the min of their blocks
// (kernels/soft/soft_common.clh, sf_plane_level).
Plane plane_level(const Plane& p, int W, int H, int w, int h);

// The fraction of the light above the receiver's tangent plane (kernels/soft/soft_common.clh,
// sf_soft_horizon): pcss and ssmm multiply their visibility by it.
double soft_horizon(const SoftOptions& opt, const Plane& plane, int W, int H);

// One receiver (background / outside = 1), tested against its plane (receiver_plane.hpp, in
// level-0 texel coordinates) with the bias opt.bias plus the plane's slope-scaled term.
// The receiver's footprint as the soft kernels take it (soft_common.clh sf_soft_footprint): a
// rectangle of texels along u and v, (f, f) for a footprint f (1 where not finite), or the
// rectangle bounding the pixel's parallelogram where the receivers carry Jacobians.
struct SoftFootprint {
  double u = 1, v = 1;
};
SoftFootprint soft_footprint(double f);
SoftFootprint soft_footprint(const Receivers& rx, size_t i);  // f, or the Jacobian's rectangle
double soft_pcss(const Planes& depth, const SoftOptions& opt, double u, double v, const Plane& plane,
                 const SoftFootprint& fp);
double soft_ssmm(const std::vector<Planes>& min_chain, const SoftOptions& opt, double u, double v, const Plane& plane,
                 const SoftFootprint& fp);
// cssm: the basis (4M + 1 planes) as cssm.cl stores it in `storage` (unorm: 0.5 + 0.5 b, then
// quantise), then the lookup through LookupRef (built with the same storage), which soft_cssm
// maps back (unorm: 2 x - 1, SoftOptions::cssm.storage); zavg_out (may be null): z_avg or NaN
// when no blocker.
Planes cssm_basis(const HostImage& depth, int order, Storage storage = Storage::F32);
class LookupRef;
double soft_cssm(const LookupRef& basis, int W, int H, const SoftOptions& opt, double u, double v, double d,
                 const SoftFootprint& fp, double* zavg_out = nullptr);

}  // namespace sf::ref

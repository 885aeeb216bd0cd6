#pragma once
// Scalar double-precision reference of the soft-shadow methods (kernels/soft/*.cl; docs/soft.md):
// the same decisions and formulas, evaluated in double.
#include "reference.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::ref {

// Area-weighted box (clamp-to-edge) of width w texels (x; y scaled by H/W) centred at (u, v) on
// a plane: lit = fraction with z >= d - bias; blk = fraction with z < d - bias, blkz = their
// weighted mean depth (NaN without blockers).
struct BoxScan {
  double lit = 0, blk = 0, zavg = 0;
};
BoxScan box_scan(const double* plane, int w, int h, double u, double v, double width, double d, double bias);

// One receiver (background / outside = 1).
double soft_pcss(const Planes& depth, const SoftOptions& opt, double u, double v, double d, double f);
double soft_ssmm(const std::vector<Planes>& min_chain, const SoftOptions& opt, double u, double v, double d, double f);
// cssm: the basis (4M + 1 planes), then the lookup through LookupRef; zavg_out (may be null):
// z_avg or NaN when no blocker.
Planes cssm_basis(const HostImage& depth, int order);
class LookupRef;
double soft_cssm(const LookupRef& basis, int W, const SoftOptions& opt, double u, double v, double d, double f,
                 double* zavg_out = nullptr);

}  // namespace sf::ref

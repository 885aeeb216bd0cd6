#pragma once
// Anisotropic footprints (docs/lookups.md "Anisotropic footprints"). A receiver's pixel covers,
// in the shadow map, the parallelogram spanned by the columns of the Jacobian of its map
// coordinates: jx = (dudx, dvdx) along the image's x and jy = (dudy, dvdy) along its y, in
// level-0 texels per pixel (Receivers::dudx ...). A floor seen at a grazing angle has one long
// column and one short: one isotropic footprint f = max(|jx|, |jy|) blurs it across as much as
// along, and a footprint of the short side aliases along. The anisotropic lookup does what
// hardware anisotropic filtering does: it cuts the parallelogram along its longer column into n
// parts and averages one lookup per part, each as wide as the parallelogram is across.
//
// footprint_probes is kernels/lookup.clh's sf_aniso_footprint in the same float operations: the
// reference and the tests read the probes the kernels read.
#include "shadowfilter/host_image.hpp"

namespace sf {

// Most probes per lookup: LookupOptions::max_anisotropy is in [1, kMaxAnisotropy].
constexpr int kMaxAnisotropy = 16;
// Jacobian components are kept within +-2^20 texels per pixel (their products stay finite in float).
constexpr float kJacobianLimit = 1048576.0f;

// How one receiver's lookup is split.
struct FootprintProbes {
  int n = 1;             // probes, 1 .. max_anisotropy
  float du = 0, dv = 0;  // step between probes along the major axis, level-0 texels
  float f = 1;           // mips: each probe's footprint (|major| / n)
  float fx = 1, fy = 1;  // box: each probe's rectangle (the bounding box of one part), texels
  // Probe k's offset from the receiver, in steps: k - (n - 1) / 2.
  float offset(int k) const { return float(k) - 0.5f * float(n - 1); }
};

// n = ceil(0.99 |major| / max(w, 1)) clamped to [1, max_anisotropy], w = |det| / |major| the
// parallelogram's width across its major column (a ratio within 1% above an integer rounds
// down: diag(f, f) gives n = 1, f, fx = fy = f, the isotropic lookup). Non-finite components
// read as the identity (footprint 1).
FootprintProbes footprint_probes(float dudx, float dvdx, float dudy, float dvdy, int max_anisotropy);

// The isotropic footprint of a Jacobian, max(|jx|, |jy|): what Receivers::f holds for
// receivers that carry a Jacobian (the footprint the isotropic lookups and the classification read).
float isotropic_footprint(float dudx, float dvdx, float dudy, float dvdy);

// A receiver whose Jacobian has a non-finite component has none known: its Jacobian becomes
// diag(f, f), which reads exactly as the isotropic lookup at f. What every reader of receivers
// does (receiver images, the Python binding).
void isotropic_where_unknown(Receivers& rx);

// The Jacobian as the device reads it (DeviceReceivers::jacobian): dudx, dvdx, dudy, dvdy one
// plane after the other, written into `planes` (resized to 4 count; its storage is reused).
void jacobian_planes(const Receivers& rx, std::vector<float>& planes);

// Receivers::f from the Jacobian channels where the receivers carry them (isotropic_footprint).
void footprint_from_jacobian(Receivers& rx);

}  // namespace sf

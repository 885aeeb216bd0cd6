#pragma once
// ReceiverPlaneOptions as the kernels take them (sf_plane_params, kernels/receiver_plane.clh) and
// their bounds, for every wrapper whose kernels test texels against the receiver's plane (sm,
// pcf, pcss, ssmm, the ESM classification's fall-back).
#include <cmath>
#include <string>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/options.hpp"
#include "shared_types.clh"

namespace sf::detail {

// A slope-scaled bias of more texels than a wide filter's radius would move every shadow edge
// further than the filter blurs it.
constexpr float kMaxSlopeBias = 16.0f;

// Throws InputError naming `name` (the options' path for the caller, e.g. "FilterOptions::receiver_plane").
inline void validate(const ReceiverPlaneOptions& o, const std::string& name) {
  if (!(o.max_slope > 0.0f) || !std::isfinite(o.max_slope))
    throw InputError(name + ".max_slope must be a positive number, got " + std::to_string(o.max_slope));
  if (!(o.slope_bias >= 0.0f && o.slope_bias <= kMaxSlopeBias))
    throw InputError(name + ".slope_bias must be in [0, " + std::to_string(int(kMaxSlopeBias)) + "] texels, got " +
                     std::to_string(o.slope_bias));
}

// row: receivers per row of the receiver image (0: unstructured points; grid kernels ignore it).
inline sf_plane_params plane_params(const ReceiverPlaneOptions& o, int row) {
  sf_plane_params p{};
  p.on = o.enabled ? 1 : 0;
  p.row = row;
  p.max_slope = o.max_slope;
  p.slope_bias = o.slope_bias;
  return p;
}

}  // namespace sf::detail

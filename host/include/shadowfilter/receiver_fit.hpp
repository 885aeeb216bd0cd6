#pragma once
// How a set of receivers sits against the map it is filtered with: the numbers behind the
// warnings about inputs that were likely misread (u, v in texels, d in another encoding than the
// map's). Host arrays only.
#include <cstddef>

#include "shadowfilter/host_image.hpp"

namespace sf {

struct ReceiverFit {
  size_t receivers = 0;   // all of them
  size_t background = 0;  // non-finite d, u or v
  size_t outside = 0;     // u or v outside [0, 1]
  size_t inside = 0;      // the rest: receivers the map can say something about
  // Inside receivers whose d lies in front of every texel of the 2x2 bilinear neighbourhood of
  // (u, v) by more than the tolerance. On a consistent scene there are none: the light's ray to a
  // receiver meets the receiver itself (or something before it).
  size_t in_front = 0;
  size_t behind = 0;  // ... behind every texel of it: receivers in shadow
  // Ranges over the receivers that are not background (NaN when there are none).
  double u_min = 0, u_max = 0, v_min = 0, v_max = 0, d_min = 0, d_max = 0;
};

// `tolerance`: in units of d.
ReceiverFit receiver_fit(const HostImage& depth, const Receivers& receivers, double tolerance = 2e-3);

}  // namespace sf

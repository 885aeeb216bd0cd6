#pragma once
// Every knob of a filtering run, with its default and why (in the spirit of Filament's
// shadow Options.h). Method-specific structs sit beside the generic ones.
#include <string>

namespace sf {

struct EsmOptions {
  // Exponent c of exp(c z). Larger: sharper, less light leaking, but a wider failure band near
  // contact. 80 is the seed's float32 value; the centred storage holds c <= 174 in float32.
  float c = 80.0f;
};

struct BlurOptions {
  // Gaussian taps -R..R applied to the basis images before the lookup; 0 = no prefilter.
  int radius = 0;
  // Standard deviation in texels; 0 = (2R+1)/6, so that the taps span +-3 sigma.
  float sigma = 0.0f;
};

// How the kernels are scheduled (Halide-style: what is computed does not depend on these).
struct ScheduleOptions {
  // Texels per work-item along a row in the blur (4, 8 or 16): wide vector loads on CPUs.
  int blur_vector_width = 16;
  // Work-group size for 1-D kernels; 0 lets the driver choose.
  int work_group_size = 0;
};

struct FilterOptions {
  std::string method = "esm";  // see `shadowfilter methods`
  EsmOptions esm;
  BlurOptions blur;
  ScheduleOptions schedule;
};

}  // namespace sf

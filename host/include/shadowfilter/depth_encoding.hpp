#pragma once
// How the depth values a renderer hands over map to the filter's depth d in [0, 1] (methods.md
// sec. 1, docs/inputs.md): d = (z - N) / (F - N) with z the distance along the light's axis, N
// and F its near and far planes. Stated by the user or by a light's projection, never guessed.
#include <limits>
#include <string>

namespace sf {

enum class DepthEncoding {
  // d as stored, in [0, 1]; with near and far planes: z itself in world units, N..F.
  Linear,
  // Window depth of a perspective projection, near -> 0, far -> 1: OpenGL's with the default
  // glDepthRange(0, 1) and D3D's / Vulkan's [0, 1] depth are the same hyperbola,
  // w = F (z - N) / (z (F - N)).
  Perspective,
  // OpenGL's normalised device z of a perspective projection, in [-1, 1]: w = (z_ndc + 1) / 2.
  PerspectiveNdc,
  // Reversed-Z window depth of a perspective projection, near -> 1, far -> 0:
  // w = N (F - z) / (z (F - N)).
  Reversed,
  // Reversed-Z with an infinite far plane: w = N / z (0 = infinitely far: nothing hit). F is not
  // the projection's: it is the depth that becomes d = 1, the range the filter works in.
  ReversedInfinite,
  // Reversed-Z window depth of an orthographic projection: w = (F - z) / (F - N), i.e. 1 - d.
  // Planes are optional (they name the light's planes; the decoding does not need them).
  ReversedLinear,
};

struct DepthDecoding {
  DepthEncoding encoding = DepthEncoding::Linear;
  // World units along the axis; NaN = not given (Linear then means d as stored, in [0, 1]).
  double near_plane = std::numeric_limits<double>::quiet_NaN();
  double far_plane = std::numeric_limits<double>::quiet_NaN();
  // Stored values beyond the far plane mean "nothing hit" (d = 1) instead of an error: a
  // renderer's own marker for empty texels (Blender's Z pass writes 1e10 there).
  bool beyond_far_is_empty = false;
};

// "linear", "perspective", "perspective-ndc", "reversed", "reversed-infinite", "reversed-linear".
const char* depth_encoding_name(DepthEncoding encoding);
// False for an unknown name.
bool parse_depth_encoding(const std::string& name, DepthEncoding* encoding);
// Every name, comma-separated, for messages and help.
std::string depth_encoding_names();

// True when the decoding has near and far planes (Linear without them is d as stored).
bool has_planes(const DepthDecoding& decoding);

// InputError unless the planes fit the encoding: Linear and ReversedLinear take both or neither
// (finite, N < F); the others need both with 0 < N < F. Messages name the fields
// (DepthDecoding::near_plane, ...).
void validate(const DepthDecoding& decoding);

// The values an encoding stores, [lo, hi]: [0, 1], [-1, 1] (PerspectiveNdc) or [N, F] (Linear with
// planes). ReversedInfinite stores (N / F .. 1] and 0.
struct StoredRange {
  double lo = 0.0, hi = 1.0;
};
StoredRange stored_range(const DepthDecoding& decoding);

// d of one stored value, in double precision, without range checks: a value outside the stored
// range decodes to d outside [0, 1] (past the far plane's pole, to a d of the wrong sign). NaN
// and infinities give NaN.
double decode_depth(double stored, const DepthDecoding& decoding);

}  // namespace sf

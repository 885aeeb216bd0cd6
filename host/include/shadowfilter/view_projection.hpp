#pragma once
// A camera or a light as renderers describe it: view and projection matrices, row-major,
// p_clip = projection x view x p_world with column vectors, and the clip space they target
// (methods.md sec. 1, docs/inputs.md). host/io reads them from JSON (view_projection_io.hpp).
#include <array>
#include <limits>
#include <optional>

#include "shadowfilter/depth_encoding.hpp"

namespace sf {

enum class ClipSpace {
  OpenGL,  // z_ndc in [-1, 1], window depth (z_ndc + 1) / 2; y_ndc = +1 is the picture's top row
  D3D,     // z_ndc in [0, 1] is the window depth; y_ndc = +1 is the top row
  Vulkan,  // z_ndc in [0, 1] is the window depth; y_ndc = -1 is the top row
};
const char* clip_space_name(ClipSpace clip);  // "opengl", "d3d", "vulkan"

struct ViewProjection {
  std::array<double, 16> view{};        // row-major
  std::array<double, 16> projection{};  // row-major
  ClipSpace clip = ClipSpace::OpenGL;
  // Reversed-Z as the file states it (near -> window depth 1). Unstated: read from a perspective
  // projection (where the near plane's window depth shows it), false for an orthographic one.
  // Stated, it must agree with a perspective projection.
  std::optional<bool> reversed_z;
  // Only for a projection with an infinite far plane: the distance along the axis that becomes
  // d = 1 (the depth range the filter works in). NaN otherwise.
  double infinite_far_depth = std::numeric_limits<double>::quiet_NaN();
};

// What a projection does to depth along its axis.
struct ProjectionDepth {
  bool perspective = false;
  bool reversed = false;
  bool infinite_far = false;
  // Distances along the view axis of window depth's near and far ends (far: infinite_far_depth
  // for an infinite far plane, infinity without it). Orthographic near planes may be <= 0.
  double near_plane = 0.0, far_plane = 0.0;
  // The view-space z of a point in front of the eye is forward x its distance: -1 for OpenGL's
  // right-handed views, +1 for D3D's left-handed ones.
  double forward = -1.0;
};

// Checks the matrices (finite, view's last row 0 0 0 1, invertible, a projection whose depth
// depends on view z alone: a standard perspective or orthographic one) and returns its depth.
// InputError with a one-line reason (a transposed, column-major matrix is named as a likely cause).
ProjectionDepth projection_depth(const ViewProjection& vp);

// projection_depth() of a light, whose d needs a finite far plane: InputError for an infinite far
// plane without ViewProjection::infinite_far_depth.
ProjectionDepth light_projection_depth(const ViewProjection& light);

// The encoding of a light's depth buffer (window depth of its projection), with its planes:
// orthographic -> Linear in [0, 1] (ReversedLinear when reversed), perspective -> Perspective
// (Reversed, ReversedInfinite).
DepthDecoding window_depth_decoding(const ViewProjection& light);

}  // namespace sf

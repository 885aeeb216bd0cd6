#pragma once
// Receivers from a camera: the surface seen through each pixel of a camera's depth buffer,
// projected into a light's shadow map (methods.md sec. 1, docs/inputs.md). Host arrays in, host
// arrays out: no files, no device; rows run on threads.
//
// For pixel (x, y) of a W x H camera image (row 0 = the picture's top row):
//   - its world point P: the pixel centre's ray at the stored depth (window depth unprojected
//     through the inverse of projection x view; or view depth / distance along the ray in world
//     units; or the world position itself);
//   - u, v: P through the light's view and projection, u = (x_ndc + 1) / 2 and v = (1 - y_ndc) / 2
//     (v = (1 + y_ndc) / 2 for Vulkan clip space): texel (i, j) of the map has its centre at
//     ((i + 1/2) / W_map, (j + 1/2) / H_map), row 0 the top of the light's picture;
//   - d = (z - N) / (F - N): z the distance of P along the light's axis, N and F its planes (the
//     same d as the light's depth buffer decoded with window_depth_decoding);
//   - f: the footprint in level-0 texels of a map of the given size: the rays through the
//     midpoints of the pixel's left and right (top and bottom) edges meet P's tangent plane, the
//     points are projected into the map, f = the larger of the two distances (capped at the
//     map's larger side);
//   - dudx dvdx dudy dvdy: the same two pairs' differences in texels, the Jacobian of the map
//     coordinates over the pixel (footprint.hpp; columns shortened to the cap, diag(f, f) where a
//     pair is not finite);
//   - ndl: the unit normal (turned towards the camera: surfaces are two-sided) dotted with the
//     unit direction from P to the light;
//   - nx, ny, nz: that normal in light space scaled to one texel, the change of (u W, v H, d) when
//     P moves one texel's world width along it (normal_offset.hpp; the normal offset's input);
//     NaN without a normal or outside the map.
// Normals come from the depth buffer (per axis the central difference where both neighbours lie
// on P's surface, else the one-sided difference towards the neighbour that continues it best) or
// from a normal image. Background pixels (see CameraDepth) have u = v = d = f = ndl = nx = ny =
// nz = NaN, and a NaN Jacobian.
// A point the light's map cannot hold (behind a perspective light, in front of its near plane or
// beyond its far plane) is outside: u = v = -1, d = 0 (the filter lights it, as any receiver
// outside the map).
#include <cstddef>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/view_projection.hpp"

namespace sf {

enum class CameraDepthKind {
  Window,    // the depth buffer: window depth of the camera's projection; background = its far
             // end (1, or 0 with reversed-Z) or non-finite
  View,      // distance along the camera's axis, world units (Blender's Z pass); background =
             // non-finite, <= 0 or beyond the camera's far plane (Blender writes 1e10 there)
  Distance,  // distance from the eye along the pixel's ray, world units (perspective cameras);
             // background as View
  Position,  // world position, 3 channels x y z; background = non-finite
};
const char* camera_depth_kind_name(CameraDepthKind kind);  // window, view, distance, position

struct CameraDepth {
  int width = 0, height = 0;
  CameraDepthKind kind = CameraDepthKind::Window;
  std::vector<float> values;  // width x height (x 3 for Position, interleaved), row 0 = the top row
};

struct CameraReceiverOptions {
  int map_width = 0, map_height = 0;  // the shadow map's size: footprints are in its texels
  // World-space normals (3 interleaved floats per pixel, any length, either orientation);
  // empty: reconstructed from the depth buffer.
  std::vector<float> normals;
  int threads = 0;  // 0: std::thread::hardware_concurrency()
};

struct CameraReceiverCounts {
  size_t background = 0;  // background pixels
  size_t outside = 0;     // points outside the light's frustum (u, v outside [0, 1] included)
  size_t no_normal = 0;   // pixels without a neighbour on their surface: f at the pixel's own depth, ndl NaN
};

// The receivers of every camera pixel: width x height of the camera image, u v d f ndl.
// InputError (one line, naming fields such as CameraDepth::kind) for a light or camera whose
// matrices projection_depth refuses, an empty or inconsistent image, window depth outside [0, 1]
// beyond rounding, a Distance image of an orthographic camera, or a missing map size.
Receivers camera_receivers(const ViewProjection& camera, const CameraDepth& depth, const ViewProjection& light,
                           const CameraReceiverOptions& options, CameraReceiverCounts* counts = nullptr);

}  // namespace sf

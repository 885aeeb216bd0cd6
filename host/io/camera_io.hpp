#pragma once
// A camera's and a light's files (docs/inputs.md): their JSON (view and projection matrices),
// the camera's depth buffer and an optional normal image. InputError with one line naming the
// file on bad input, as everywhere in host/io.
#include <string>
#include <vector>

#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/view_projection.hpp"

namespace sf::io {

// A camera or light file:
//   {"view": [16 numbers], "projection": [16 numbers],      row-major (or 4 rows of 4),
//    "clip": "opengl" | "d3d" | "vulkan",                    optional, default opengl
//    "reversed_z": true | false,                             optional (see ViewProjection)
//    "far": F,                                               only for an infinite far plane
//    "width": W, "height": H}                                optional: the image's size, checked
struct ViewFile {
  ViewProjection view_projection;
  int width = 0, height = 0;  // 0: not stated
};

// Parses the text of a file; `source` names it in messages ("light 'sun.json'"). Refuses what is
// not that object: JSON errors, unknown keys, nesting deeper than 8 levels, matrices that are not
// 16 finite numbers, matrices projection_depth() refuses (a transposed one among them). Needs no
// file: the text may come from anywhere.
ViewFile parse_view_file(const std::string& text, const std::string& source);

// Reads and parses a file (at most 1 MiB); `role` is "camera" or "light".
ViewFile load_view_file(const std::string& path, const std::string& role);

// "window" | "view" | "distance" | "position" (InputError naming them otherwise).
CameraDepthKind parse_camera_depth_kind(const std::string& name);

// The camera's depth buffer: one channel (or the one named Z, as a shadow map), 3 for positions
// (P.x P.y P.z, X Y Z, or the first three), at least 16 bits per value. Its range is checked by
// camera_receivers().
CameraDepth load_camera_depth(const std::string& path, CameraDepthKind kind);

// A world-space normal image of width x height (N.x N.y N.z, X Y Z, or the first three of 3-4
// channels), 3 floats per pixel.
std::vector<float> load_normal_image(const std::string& path, int width, int height);

// The size of an image (a shadow map whose texels a camera's footprints are measured in).
void image_size(const std::string& path, const std::string& role, int* width, int* height);

}  // namespace sf::io

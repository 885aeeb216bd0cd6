#pragma once
// Image I/O: the only code in shadowfilter that touches files (OpenImageIO).
// Every function throws sf::InputError with a one-line message naming the file on bad input.
#include <string>
#include <vector>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/host_image.hpp"

namespace sf::io {

// How the depth values in a file map to linear light-space depth in [0,1] (methods.md sec. 1).
enum class DepthEncoding { Linear, Perspective, Reversed };
// What to do with NaN/Inf depth texels in a shadow map.
enum class NonFinitePolicy { Error, Far };

struct DepthLoadOptions {
  DepthEncoding encoding = DepthEncoding::Linear;
  double near_plane = 0.1;   // --near, perspective/reversed only
  double far_plane = 100.0;  // --far, perspective/reversed only
  NonFinitePolicy nonfinite = NonFinitePolicy::Error;
};

DepthEncoding parse_depth_encoding(const std::string& name);  // "linear"|"perspective"|"reversed"

// Converts one stored depth value to linear normalised depth (methods.md sec. 1).
double linearize_depth(double stored, const DepthLoadOptions& opt);

// Reads a shadow map (EXR, TIFF, PFM, PNG, HDR, anything OpenImageIO reads): one channel, or
// three identical channels (RGB-only formats such as HDR). Result: 1 channel, linear depth,
// clamped to [0,1]; non-finite texels are an error unless opt.nonfinite == Far (then 1).
HostImage load_depth_map(const std::string& path, const DepthLoadOptions& opt);

// Reads a receiver image: float EXR/TIFF/PFM with 3, 4 or 5 channels. Channels named
// u v d [f [ndl]] are used by name (in any order), else positional: R G B [A [5th]]. Missing
// footprint = 1; ndl (n.l towards the light, <= 0 facing away) only with 5 channels.
Receivers load_receiver_image(const std::string& path);

// --receiver-depth mode: one-channel image of the shadow map's size (expected_w x expected_h);
// decoded with the same encoding as the shadow map; non-finite texels are background.
Receivers load_receiver_depth(const std::string& path, int expected_w, int expected_h, const DepthLoadOptions& opt);

// The receivers of a run: the receiver image `receivers`, or, when that is empty, the planar
// receivers of `receiver_depth` on the grid of `depth` (decoded with `opt`, as the map).
Receivers load_receivers(const std::string& receivers, const std::string& receiver_depth, const HostImage& depth,
                         const DepthLoadOptions& opt);

// Writes an image atomically (temporary file in the same directory, then rename).
// Format from the extension: .exr (float32), .tif/.tiff (float32), .pfm, .png (16-bit).
void write_image(const std::string& path, const HostImage& img);

// Several images written as one: each to its temporary file first, then all moved into place, so
// an image that cannot be written leaves none of them (a frame's visibility with its preview
// and flags).
struct ImageToWrite {
  std::string path;
  const HostImage* image = nullptr;
};
void write_images(const std::vector<ImageToWrite>& images);

// The preview of a visibility image: OUTPUT with the extension .png (16-bit grey, [0,1]).
// InputError when the output is a PNG already.
std::string preview_path(const std::string& output);

}  // namespace sf::io

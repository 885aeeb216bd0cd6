#pragma once
// Image I/O: the only code in shadowfilter that touches files (OpenImageIO).
// Every function throws sf::InputError with a one-line message naming the file on bad input.
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/depth_encoding.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/host_image.hpp"

namespace sf::io {

// How the depth values in a file map to the filter's d in [0, 1] (methods.md sec. 1,
// shadowfilter/depth_encoding.hpp, docs/inputs.md).
using DepthEncoding = sf::DepthEncoding;
// What to do with NaN/Inf depth texels in a shadow map.
enum class NonFinitePolicy { Error, Far };

struct DepthLoadOptions {
  DepthEncoding encoding = DepthEncoding::Linear;
  // --near / --far, world units along the light's axis; NaN = not given (never a default).
  double near_plane = std::numeric_limits<double>::quiet_NaN();
  double far_plane = std::numeric_limits<double>::quiet_NaN();
  bool beyond_far_is_empty = false;  // --beyond-far far: stored values past the far plane = nothing hit
  NonFinitePolicy nonfinite = NonFinitePolicy::Error;
  // How messages name where the encoding came from: a flag (--encoding, --receiver-encoding,
  // followed by the encoding's name), or a text of its own (a light file's projection).
  std::string flag = "--encoding";

  DepthDecoding decoding() const;
};

DepthEncoding parse_depth_encoding(const std::string& name);  // InputError naming every valid name

// d of one stored value (sf::decode_depth): no range check, no clamp.
double linearize_depth(double stored, const DepthLoadOptions& opt);

// Reads a shadow map (EXR, TIFF, PFM, PNG, HDR, anything OpenImageIO reads): one channel, or
// three identical channels (RGB-only formats such as HDR), at least 16 bits per depth. Result: 1
// channel, d in [0, 1]. Stored values outside the encoding's range beyond rounding (1e-6 of the
// range) are an InputError naming the range found and the likely fix, never clamped (within
// rounding they are clamped to the range); values past the far plane with beyond_far_is_empty
// and non-finite texels with nonfinite == Far become 1, else non-finite texels are an error.
HostImage load_depth_map(const std::string& path, const DepthLoadOptions& opt);

// What a receiver image's header says about it (written by `shadowfilter receivers`).
struct ReceiverHeader {
  bool normalized = false;            // "shadowfilter:d" = "normalized": d already in [0, 1]
  int map_width = 0, map_height = 0;  // "shadowfilter:map_size": the map size its footprints are in texels of
  double light_near = std::numeric_limits<double>::quiet_NaN();  // "shadowfilter:light_near", world units
  double light_far = std::numeric_limits<double>::quiet_NaN();   // "shadowfilter:light_far"
};
// The header attributes of receivers made for a light's map of map_width x map_height.
std::map<std::string, std::string> receiver_header_attributes(int map_width, int map_height, double light_near,
                                                              double light_far);

// Reads a receiver image: float EXR/TIFF/PFM with 3, 4, 5 or 8 channels. Channels named
// u v d [f [ndl [nx ny nz]]] are used by name (in any order), else positional: R G B [A [5th
// [6th-8th]]]. Missing footprint = 1; ndl (n.l towards the light, <= 0 facing away) with 5 or 8
// channels; the texel-scaled normal nx ny nz (normal_offset.hpp) with 8, whose d must then be
// normalized linear depth.
// d is decoded with `stated` when given (--receiver-encoding), else as the header says
// (normalized), else with the map's `decoding`; a decoded d outside [0, 1] beyond rounding is an
// InputError, non-finite u, v, f or d make the receiver background.
Receivers load_receiver_image(const std::string& path, const DepthLoadOptions& decoding = {},
                              const std::optional<DepthLoadOptions>& stated = std::nullopt,
                              ReceiverHeader* header = nullptr);

// --receiver-depth mode: one-channel image of the shadow map's size (expected_w x expected_h),
// at least 16 bits; decoded with `opt` (the map's encoding, or --receiver-encoding), range
// checked as a map; non-finite texels are background.
Receivers load_receiver_depth(const std::string& path, int expected_w, int expected_h, const DepthLoadOptions& opt);

// The receivers of a run: the receiver image `receivers`, or, when that is empty, the planar
// receivers of `receiver_depth` on the grid of `depth` (decoded with `opt`, as the map, unless
// `stated` says otherwise).
Receivers load_receivers(const std::string& receivers, const std::string& receiver_depth, const HostImage& depth,
                         const DepthLoadOptions& opt, const std::optional<DepthLoadOptions>& stated = std::nullopt,
                         ReceiverHeader* header = nullptr);

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

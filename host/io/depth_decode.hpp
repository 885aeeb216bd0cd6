#pragma once
// Decoding the depths of a file to the filter's d (image_io.hpp's loaders): the stated encoding,
// a range check that names what was found and the likely fix, never a silent clamp.
#include <string>
#include <vector>

#include "image_io.hpp"
#include "io_detail.hpp"

namespace sf::io::detail {

// The single depth channel of an image: its only channel; else the one channel named Z (or
// ending in .Z: Blender's multilayer "ViewLayer.Depth.Z") or depth; else the first of 3-4
// channels whose first three agree everywhere (RGB-only formats such as Radiance HDR).
std::vector<float> single_depth_channel(const RawImage& img, const std::string& path, const std::string& role);

// The indices of three channels: named by one of `names` (each a triple, e.g. {"P.x", "P.y",
// "P.z"}), else the first three of a 3- or 4-channel image; InputError otherwise.
std::vector<int> three_channels(const RawImage& img, const std::vector<std::vector<std::string>>& names,
                                const std::string& path, const std::string& role);

// InputError unless the file stores at least 16 bits per depth (8-bit images hold 256 depth
// levels: every receiver within 1/256 of the range would shadow itself or not at random).
void require_16_bit_depth(const RawImage& img, const std::string& role, const std::string& path);

// Decodes `values` in place to d in [0, 1]. Stored values outside the encoding's range by more
// than rounding (1e-6 of the range, a few float ulps) are an InputError naming the range found,
// the encoding's and the likely fix (`receivers`: the hints speak of --receiver-encoding);
// within rounding they are clamped. Non-finite values become NaN; values past the far plane with
// beyond_far_is_empty become `empty` (1 for a map, NaN, i.e. background, for receivers).
// InputError too when the encoding's planes are invalid (DepthDecoding's validate()).
void decode_depths(std::vector<float>& values, const DepthLoadOptions& opt, const std::string& role,
                   const std::string& path, float empty, bool receivers);

}  // namespace sf::io::detail

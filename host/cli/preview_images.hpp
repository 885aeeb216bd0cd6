#pragma once
// `--preview [shaded]`: pictures written beside an output for a person to look at.
//   plain  (--preview): OUTPUT.png, the visibility in 16-bit grey.
//   shaded (--preview shaded): the plain one and OUTPUT_shaded.png beside it: a grey surface
//          lit by the light, albedo x (ambient + (1 - ambient) x visibility x max(ndl, 0)), with
//          the background in a colour of its own, so that shadows read as shadows on objects
//          instead of black blobs on white.
#include <string>
#include <vector>

#include "image_io.hpp"
#include "shadowfilter/host_image.hpp"

namespace sf::cli {

enum class PreviewKind { None, Plain, Shaded };

// The --preview value: "none" (not given), "" or "plain" (given alone), "shaded"; InputError else.
PreviewKind parse_preview(const std::string& value);

// The files a preview writes beside `output` (InputError when the output is a PNG already).
std::vector<std::string> preview_paths(const std::string& output, PreviewKind kind);

// The shaded picture (RGB) of a visibility image. `probe`: a value per pixel that is NaN on
// background (a receiver's d, a view's position); `ndl`: n.l per pixel, empty or NaN where
// unknown (then the surface is shaded as if it faced the light).
HostImage shaded_preview(const HostImage& visibility, const std::vector<float>& probe, const std::vector<float>& ndl);

// The images to write for an output: the output, then its previews (the shaded one made from
// `receivers`), in the order of preview_paths. `keep` holds the shaded image while it is written.
std::vector<io::ImageToWrite> output_with_previews(const std::string& output, const HostImage& visibility,
                                                   PreviewKind kind, const std::vector<float>& probe,
                                                   const std::vector<float>& ndl, HostImage* keep);

}  // namespace sf::cli

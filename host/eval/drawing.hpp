#pragma once
// What evaluate's pictures share: text in DejaVu Sans, method colours, and the atomic 8-bit PNG
// writer (a picture for people: 8 bits per channel is what a viewer shows, and a half-written
// file never takes the place of a good one).
#include <OpenImageIO/imagebuf.h>

#include <string>
#include <vector>

namespace sf::eval::draw {

// Text with its baseline at (x, y); a machine without the font still gets the rest of the picture.
void text(OIIO::ImageBuf& img, int x, int y, const std::string& s, const std::vector<float>& colour, int size = 14);
// Width in pixels of `s` at `size` (an estimate of 0.6 size per character without the font).
int text_width(const std::string& s, int size);
std::vector<float> method_colour(const std::string& method);
// `img` (RGB, any pixel type, values in [0,1]) as an 8-bit RGB PNG at `path`, "ImageDescription"
// set to `description`: written to a temporary file beside it, then renamed over it. Throws
// InputError naming `path`.
void write_png8(const std::string& path, const OIIO::ImageBuf& img, const std::string& description);

}  // namespace sf::eval::draw

#pragma once
// The size an image header declares, checked before any pixel is allocated (internal to host/io).
#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <memory>
#include <string>

namespace sf::io::detail {

// The fewest bytes a file of this format and compression can hold the declared pixels in (0 when
// the format gives no such bound): the pixels themselves where the format stores them as they are
// (PFM and binary PNM, uncompressed EXR and TIFF), the pixels divided by the most the compression
// can shrink them (deflate in PNG, zip EXR and TIFF: 1032 to 1; EXR rle and TIFF packbits: 64 to
// 1), a character a sample for text PNM, and for Radiance HDR 4 bytes a pixel (flat scanlines) or
// a 4-byte scanline header and 4 runs of 2 bytes per 127 pixels (run-length scanlines, widths 8 to
// 32767). PNG, and TIFF other than grey or RGB (palettes, subsampled YCbCr), may store less than
// the channels they are read as: 1 bit a pixel is assumed for them.
uint64_t minimum_file_bytes(const OIIO::ImageSpec& spec, const std::string& format_name);

// InputError naming role and path when the declared width x height x channels as float is over
// the memory budget (input_file.hpp), or when the file is smaller than minimum_file_bytes.
void check_declared_image_size(const OIIO::ImageSpec& spec, const std::string& format_name, uint64_t file_bytes,
                               const std::string& path, const std::string& role);

// Opens an image after every check that needs no pixels: a regular file (require_regular_file),
// an OpenEXR header walked before OpenEXR reads it (exr_header.hpp), a readable plain 2D image
// (not deep, not a volume, not empty), its declared size as check_declared_image_size wants it.
// read_raw reads the pixels from it; readers of a header alone (soft's light) use it directly.
std::unique_ptr<OIIO::ImageInput> open_checked_image(const std::string& path, const std::string& role);

}  // namespace sf::io::detail

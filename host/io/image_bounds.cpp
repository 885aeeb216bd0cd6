#include "image_bounds.hpp"

#include <algorithm>
#include <cctype>

#include "input_file.hpp"
#include "io_detail.hpp"

namespace sf::io::detail {
namespace {

// deflate codes a 258-byte match in 2 bits at best (a 1-bit length code and a 1-bit distance
// code): 1032 to 1 is the most it shrinks anything.
constexpr uint64_t kDeflateRatio = 1032;
// EXR rle and TIFF packbits code a run of at most 128 equal bytes in 2 bytes.
constexpr uint64_t kRunLengthRatio = 64;
// Radiance HDR: run-length scanlines (widths 8 to 32767) code each of their 4 components in
// runs of at most 127 (2 bytes each) after a 4-byte scanline header; other widths are flat.
constexpr uint64_t kHdrMaxRun = 127;

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

uint64_t saturating_multiply(uint64_t a, uint64_t b) {
  uint64_t product = 0;
  return multiply_fits(a, b, &product) ? product : UINT64_MAX;
}

// The fewest bits a pixel of the file can take: what the header declares (oiio:BitsPerSample
// bits a channel, or the channels' own types), except where the file may store less than the
// channels it is read as: PNG (palette indices and bitmaps of 1 bit a pixel) and TIFF other than
// grey or RGB (palettes, subsampled YCbCr), 1 bit a pixel.
uint64_t bits_per_pixel_at_least(const OIIO::ImageSpec& spec, const std::string& format) {
  if (format == "png") return 1;
  if (format == "tiff" && spec.get_int_attribute("tiff:PhotometricInterpretation", -1) > 2) return 1;
  if (!spec.channelformats.empty()) {
    uint64_t bits = 0;
    for (const OIIO::TypeDesc& channel : spec.channelformats) bits += 8 * channel.size();
    return bits;
  }
  const int bits = spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
  return saturating_multiply(uint64_t(std::max(bits, 1)), uint64_t(spec.nchannels));
}

// Bytes of the pixels stored as they are: rows of width pixels, each row padded to a whole byte.
uint64_t stored_pixel_bytes(const OIIO::ImageSpec& spec, const std::string& format) {
  const uint64_t row_bits = saturating_multiply(uint64_t(spec.width), bits_per_pixel_at_least(spec, format));
  const uint64_t row_bytes = row_bits == UINT64_MAX ? row_bits : (row_bits + 7) / 8;
  return saturating_multiply(row_bytes, uint64_t(spec.height));
}

uint64_t hdr_scanline_bytes(uint64_t width) {
  if (width < 8 || width > 0x7fff) return 4 * width;
  return 4 + 8 * ((width + kHdrMaxRun - 1) / kHdrMaxRun);
}

// How many times smaller than its pixels a file of this format and compression can be; 0: no bound.
uint64_t max_shrink(const OIIO::ImageSpec& spec, const std::string& format) {
  const std::string compression = lower(spec.get_string_attribute("compression"));
  if (format == "pnm") return 1;
  if (format == "png") return kDeflateRatio;
  if (format == "openexr" || format == "tiff") {
    if (compression == "none") return 1;
    if (compression == "zip" || compression == "zips" || compression == "deflate") return kDeflateRatio;
    if ((format == "openexr" && compression == "rle") || (format == "tiff" && compression == "packbits"))
      return kRunLengthRatio;
  }
  return 0;
}

std::string channel_text(int channels) { return std::to_string(channels) + (channels == 1 ? " channel" : " channels"); }

}  // namespace

uint64_t minimum_file_bytes(const OIIO::ImageSpec& spec, const std::string& format_name) {
  const std::string format = lower(format_name);
  if (format == "hdr") return saturating_multiply(hdr_scanline_bytes(uint64_t(spec.width)), uint64_t(spec.height));
  if (format == "pnm" && spec.get_int_attribute("pnm:binary", 1) == 0)  // text: a character per sample at least
    return saturating_multiply(saturating_multiply(uint64_t(spec.width), uint64_t(spec.height)),
                               uint64_t(spec.nchannels));
  const uint64_t shrink = max_shrink(spec, format);
  if (shrink == 0) return 0;
  return stored_pixel_bytes(spec, format) / shrink;
}

void check_declared_image_size(const OIIO::ImageSpec& spec, const std::string& format_name, uint64_t file_bytes,
                               const std::string& path, const std::string& role) {
  const std::string declared = "the header's " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                               " image of " + channel_text(spec.nchannels);
  const uint64_t float_bytes = saturating_multiply(
      saturating_multiply(saturating_multiply(uint64_t(spec.width), uint64_t(spec.height)), uint64_t(spec.nchannels)),
      sizeof(float));
  require_within_image_budget(float_bytes, declared, path, role);
  const uint64_t needed = minimum_file_bytes(spec, format_name);
  if (file_bytes < needed) {
    const std::string compression = spec.get_string_attribute("compression");
    fail(role, path,
         "truncated or corrupt: " + declared + " needs at least " + std::to_string(needed) + " bytes as " +
             lower(format_name) + (compression.empty() ? "" : " (" + compression + ")") + ", the file holds " +
             std::to_string(file_bytes));
  }
}

}  // namespace sf::io::detail

// Image writing: each image is encoded in memory and written through the one checked, atomic
// writer (output_file.hpp), so a failed write never leaves a partial file or clobbers an old one.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "image_io.hpp"
#include "io_detail.hpp"
#include "output_file.hpp"

namespace sf::io {
namespace {

using detail::details_suffix;
using detail::fail;
namespace fs = std::filesystem;

const char* const kOutputRole = "output image";

enum class OutputFormat { Exr, Tiff, Pfm, Png };

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return text;
}

OutputFormat format_from_extension(const std::string& path) {
  const std::string ext = lowercase(fs::path(path).extension().string());
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  if (ext == ".pfm") return OutputFormat::Pfm;
  if (ext == ".png") return OutputFormat::Png;
  fail(kOutputRole, path, "unsupported extension '" + ext + "'; supported: .exr, .tif, .tiff, .pfm, .png");
}

void require_consistent_image(const HostImage& img, const std::string& path) {
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0)
    fail(kOutputRole, path,
         "cannot write an empty image (" + std::to_string(img.width) + "x" + std::to_string(img.height) + ", " +
             std::to_string(img.channels) + " channels)");
  if (img.data.size() != img.texels() * img.channels)
    fail(kOutputRole, path,
         "image data holds " + std::to_string(img.data.size()) + " values, expected " +
             std::to_string(img.texels() * img.channels));
  const size_t channels = static_cast<size_t>(img.channels);
  if (!img.channel_names.empty() && img.channel_names.size() != channels)
    fail(kOutputRole, path,
         std::to_string(img.channel_names.size()) + " channel names for " + std::to_string(channels) + " channels");
  if (!img.channel_formats.empty() && img.channel_formats.size() != channels)
    fail(kOutputRole, path,
         std::to_string(img.channel_formats.size()) + " channel formats for " + std::to_string(channels) + " channels");
}

OIIO::TypeDesc exr_channel_type(const std::string& name, const std::string& path) {
  if (name.empty() || name == "float") return OIIO::TypeDesc::FLOAT;
  if (name == "half") return OIIO::TypeDesc::HALF;
  fail(kOutputRole, path, "unknown channel format '" + name + "'; valid: float, half");
}

// EXR stores each channel as float32 unless channel_formats asks for half.
void set_exr_channel_types(OIIO::ImageSpec& spec, const HostImage& img, const std::string& path) {
  if (img.channel_formats.empty()) return;
  std::vector<OIIO::TypeDesc> types;
  for (const std::string& name : img.channel_formats) types.push_back(exr_channel_type(name, path));
  const bool uniform = std::all_of(types.begin(), types.end(), [&](OIIO::TypeDesc t) { return t == types[0]; });
  spec.set_format(types[0]);
  if (!uniform) spec.channelformats = types;
}

OIIO::ImageSpec output_spec(const HostImage& img, OutputFormat format, const std::string& path) {
  const OIIO::TypeDesc pixel_type = format == OutputFormat::Png ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::FLOAT;
  OIIO::ImageSpec spec(img.width, img.height, img.channels, pixel_type);
  if (!img.channel_names.empty()) spec.channelnames = img.channel_names;
  // Values are written as given: a 4th channel is data (e.g. a footprint), not alpha to
  // (un)premultiply.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  switch (format) {
    case OutputFormat::Exr:
      spec.attribute("compression", "zip");
      set_exr_channel_types(spec, img, path);
      break;
    case OutputFormat::Tiff:
      spec.attribute("compression", "zip");
      break;
    case OutputFormat::Pfm:  // encoded by encode_pfm
      break;
    case OutputFormat::Png:
      if (img.channels > 4)
        fail(kOutputRole, path, "PNG holds 1 to 4 channels, the image has " + std::to_string(img.channels));
      break;
  }
  // OpenImageIO stamps files with the current time unless DateTime is given: an empty one keeps
  // an output a function of its input, byte for byte (a batch's frames equal single runs').
  spec.attribute("DateTime", "");
  for (const auto& [name, value] : img.attributes) spec.attribute(name, value);
  return spec;
}

// PNG stores unorm16: clamp to [0,1] here (NaN becomes 0) rather than rely on the converter.
std::vector<float> png_values(const std::vector<float>& data) {
  std::vector<float> clamped(data.size());
  std::transform(data.begin(), data.end(), clamped.begin(),
                 [](float v) { return v > 0.0f ? std::min(v, 1.0f) : 0.0f; });
  return clamped;
}

bool little_endian_host() {
  const std::uint32_t one = 1;
  unsigned char first_byte = 0;
  std::memcpy(&first_byte, &one, 1);
  return first_byte == 1;
}

// OIIO 2.4 reads PFM but has no PFM writer, so it is encoded here: header "Pf" (1 channel) or
// "PF" (3 channels), size, scale (negative = little-endian), then float32 rows from the bottom
// row of the image up.
std::vector<unsigned char> encode_pfm(const HostImage& img, const std::string& path) {
  if (img.channels != 1 && img.channels != 3)
    fail(kOutputRole, path, "PFM holds 1 or 3 channels, the image has " + std::to_string(img.channels));
  const std::string header = std::string(img.channels == 1 ? "Pf" : "PF") + "\n" + std::to_string(img.width) + " " +
                             std::to_string(img.height) + "\n" + (little_endian_host() ? "-1.0" : "1.0") + "\n";
  const size_t row_bytes = static_cast<size_t>(img.width) * img.channels * sizeof(float);
  std::vector<unsigned char> bytes(header.begin(), header.end());
  bytes.resize(header.size() + row_bytes * img.height);
  unsigned char* at = bytes.data() + header.size();
  for (int y = img.height - 1; y >= 0; --y, at += row_bytes)
    std::memcpy(at, img.data.data() + static_cast<size_t>(y) * img.width * img.channels, row_bytes);
  return bytes;
}

std::vector<unsigned char> encode(const std::string& path, const HostImage& img) {
  const OutputFormat format = format_from_extension(path);
  require_consistent_image(img, path);
  if (format == OutputFormat::Pfm) return encode_pfm(img, path);
  const OIIO::ImageSpec spec = output_spec(img, format, path);
  const std::vector<float> clamped = format == OutputFormat::Png ? png_values(img.data) : std::vector<float>{};
  return detail::encode_with_oiio(path, kOutputRole, spec, OIIO::TypeDesc::FLOAT,
                                  clamped.empty() ? img.data.data() : clamped.data());
}

}  // namespace

namespace detail {

// OIIO writes into memory (an IOVecOutput proxy, which the EXR, TIFF, PNG and HDR writers take),
// so that the file itself goes through the one checked writer (output_file.hpp): OIIO's own file
// writes did not report a full disk for every format.
std::vector<unsigned char> encode_with_oiio(const std::string& path, const std::string& role,
                                            const OIIO::ImageSpec& spec_in, OIIO::TypeDesc pixel_type,
                                            const void* pixels) {
  auto output = OIIO::ImageOutput::create(path);
  if (!output) fail(role, path, "cannot create an image writer" + details_suffix(OIIO::geterror()));
  if (!output->supports("ioproxy"))
    fail(role, path, std::string("the ") + output->format_name() + " writer cannot write to memory");
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  OIIO::ImageSpec spec = spec_in;
  void* proxy = &memory;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  if (!output->open(path, spec)) fail(role, path, "cannot encode" + details_suffix(output->geterror()));
  const bool write_ok = output->write_image(pixel_type, pixels);
  const std::string write_error = output->geterror();
  const bool close_ok = output->close();
  const std::string close_error = output->geterror();
  if (!write_ok || !close_ok || bytes.empty())
    fail(role, path, "cannot encode" + details_suffix(write_error.empty() ? close_error : write_error));
  return bytes;
}

}  // namespace detail

void write_image(const std::string& path, const HostImage& img) {
  const std::vector<unsigned char> bytes = encode(path, img);
  write_file(path, kOutputRole, bytes.data(), bytes.size());
}

std::string preview_path(const std::string& output) {
  if (format_from_extension(output) == OutputFormat::Png)
    fail(kOutputRole, output, "is a PNG already; --preview writes a PNG beside an .exr, .tif or .pfm output");
  return fs::path(output).replace_extension(".png").string();
}

void write_images(const std::vector<ImageToWrite>& images) {
  OutputSet set;
  for (const ImageToWrite& out : images) {
    const std::vector<unsigned char> bytes = encode(out.path, *out.image);
    set.add(out.path, kOutputRole, bytes.data(), bytes.size());
  }
  set.commit();
}

}  // namespace sf::io

// Atomic image writing: a temporary file in the output's directory, renamed over the output only
// once it is complete, so a failed write never leaves a partial file or clobbers an old one.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "image_io.hpp"
#include "io_detail.hpp"

namespace sf::io {
namespace {

using detail::details_suffix;
using detail::fail;
using detail::temporary_path_for;
using detail::TemporaryFile;
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
    case OutputFormat::Pfm:  // written by write_pfm
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

// OIIO 2.4 reads PFM but has no PFM writer, so it is written directly: header "Pf" (1 channel)
// or "PF" (3 channels), size, scale (negative = little-endian), then float32 rows from the
// bottom row of the image up.
void write_pfm(const fs::path& file, const HostImage& img, const std::string& path) {
  if (img.channels != 1 && img.channels != 3)
    fail(kOutputRole, path, "PFM holds 1 or 3 channels, the image has " + std::to_string(img.channels));
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) fail(kOutputRole, path, "cannot open for writing (" + std::string(std::strerror(errno)) + ")");
  out << (img.channels == 1 ? "Pf" : "PF") << '\n'
      << img.width << ' ' << img.height << '\n'
      << (little_endian_host() ? "-1.0" : "1.0") << '\n';
  const size_t row_values = static_cast<size_t>(img.width) * img.channels;
  for (int y = img.height - 1; y >= 0; --y)
    out.write(reinterpret_cast<const char*>(img.data.data() + y * row_values),
              static_cast<std::streamsize>(row_values * sizeof(float)));
  out.close();
  if (!out) fail(kOutputRole, path, "write failed (" + std::string(std::strerror(errno)) + ")");
}

// OIIO's messages name the temporary file; the user only knows the output path.
std::string with_output_path(std::string message, const fs::path& file, const std::string& path) {
  const std::string temporary = file.string();
  for (size_t at = message.find(temporary); at != std::string::npos; at = message.find(temporary, at + path.size()))
    message.replace(at, temporary.size(), path);
  return message;
}

void write_with_oiio(const fs::path& file, const HostImage& img, OutputFormat format, const std::string& path) {
  const OIIO::ImageSpec spec = output_spec(img, format, path);
  const std::vector<float> clamped = format == OutputFormat::Png ? png_values(img.data) : std::vector<float>{};
  const float* pixels = clamped.empty() ? img.data.data() : clamped.data();

  auto output = OIIO::ImageOutput::create(file.string());
  if (!output) fail(kOutputRole, path, "cannot create an image writer" + details_suffix(OIIO::geterror()));
  if (!output->open(file.string(), spec))
    fail(kOutputRole, path,
         "cannot open for writing" + details_suffix(with_output_path(output->geterror(), file, path)));
  const bool write_ok = output->write_image(OIIO::TypeDesc::FLOAT, pixels);
  const std::string write_error = output->geterror();
  const bool close_ok = output->close();
  const std::string close_error = output->geterror();
  if (!write_ok || !close_ok)
    fail(
        kOutputRole, path,
        "write failed" + details_suffix(with_output_path(write_error.empty() ? close_error : write_error, file, path)));
}

// The finished file at its temporary path, not yet in place.
std::unique_ptr<TemporaryFile> write_temporary(const std::string& path, const HostImage& img) {
  const OutputFormat format = format_from_extension(path);
  require_consistent_image(img, path);
  auto temporary = std::make_unique<TemporaryFile>(temporary_path_for(path));
  if (format == OutputFormat::Pfm)
    write_pfm(temporary->path(), img, path);
  else
    write_with_oiio(temporary->path(), img, format, path);
  return temporary;
}

}  // namespace

void write_image(const std::string& path, const HostImage& img) {
  auto temporary = write_temporary(path, img);
  detail::move_into_place(*temporary, path, kOutputRole);
}

std::string preview_path(const std::string& output) {
  if (format_from_extension(output) == OutputFormat::Png)
    fail(kOutputRole, output, "is a PNG already; --preview writes a PNG beside an .exr, .tif or .pfm output");
  return fs::path(output).replace_extension(".png").string();
}

void write_images(const std::vector<ImageToWrite>& images) {
  std::vector<std::unique_ptr<TemporaryFile>> written;
  for (const ImageToWrite& out : images) written.push_back(write_temporary(out.path, *out.image));
  for (size_t i = 0; i < images.size(); ++i) detail::move_into_place(*written[i], images[i].path, kOutputRole);
}

}  // namespace sf::io

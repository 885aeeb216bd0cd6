// Text, colours and the 8-bit PNG writer of evaluate's pictures (drawing.hpp).
#include "drawing.hpp"

#include <OpenImageIO/imagebufalgo.h>

#include <filesystem>
#include <map>

#include "io_detail.hpp"
#include "method_catalogue.hpp"
#include "output_file.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval::draw {
namespace fs = std::filesystem;

namespace {

std::string font_path() {
  for (const char* p :
       {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"})
    if (fs::exists(p)) return p;
  return "";  // OIIO's default font search
}

}  // namespace

void text(OIIO::ImageBuf& img, int x, int y, const std::string& s, const std::vector<float>& colour, int size) {
  OIIO::ImageBufAlgo::render_text(img, x, y, s, size, font_path(), colour);
}

int text_width(const std::string& s, int size) {
  const OIIO::ROI r = OIIO::ImageBufAlgo::text_size(s, size, font_path());
  return r.defined() ? r.width() : int(0.6 * size * double(s.size()));
}

std::vector<float> method_colour(const std::string& m) {
  // The soft methods (not in the registry): pink, gold, sky blue, slate, apart from the catalogue's.
  static const std::map<std::string, std::vector<float>> soft = {{"pcss", {0.95f, 0.35f, 0.65f}},
                                                                 {"cssm", {0.80f, 0.70f, 0.10f}},
                                                                 {"ssmm", {0.30f, 0.70f, 0.95f}},
                                                                 {"ssmm-improved", {0.25f, 0.30f, 0.45f}}};
  if (const auto it = soft.find(m); it != soft.end()) return it->second;
  const auto& c = catalogue_entry(method(m)).colour;
  return {c[0], c[1], c[2]};
}

void write_png8(const std::string& path, const OIIO::ImageBuf& img, const std::string& description) {
  OIIO::ImageBuf out(OIIO::ImageSpec(img.spec().width, img.spec().height, 3, OIIO::TypeDesc::UINT8));
  OIIO::ImageBufAlgo::clamp(out, img, 0.0f, 1.0f);
  std::vector<unsigned char> pixels(size_t(out.spec().width) * out.spec().height * 3);
  if (!out.get_pixels(out.roi(), OIIO::TypeDesc::UINT8, pixels.data()))
    throw InputError("cannot write '" + path + "': " + out.geterror());
  OIIO::ImageSpec spec = out.spec();
  spec.attribute("ImageDescription", description);
  spec.attribute("DateTime", "");
  const std::vector<unsigned char> bytes =
      io::detail::encode_with_oiio(path, "plot", spec, OIIO::TypeDesc::UINT8, pixels.data());
  io::write_file(path, "plot", bytes.data(), bytes.size());
}

}  // namespace sf::eval::draw

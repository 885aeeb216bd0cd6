// Text, colours and the 8-bit PNG writer of evaluate's pictures (drawing.hpp).
#include "drawing.hpp"

#include <OpenImageIO/imagebufalgo.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>

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
  const auto& c = find_method(m).colour;
  return {c[0], c[1], c[2]};
}

void write_png8(const std::string& path, const OIIO::ImageBuf& img, const std::string& description) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  // ".<stem>.tmp.<pid>.<n>.png" beside the output: the same file system (the rename is atomic)
  // and the extension last (OIIO picks the format from it).
  const fs::path tmp = target.parent_path() / ("." + target.stem().string() + ".tmp." + std::to_string(::getpid()) +
                                               "." + std::to_string(counter++) + ".png");
  OIIO::ImageBuf out(OIIO::ImageSpec(img.spec().width, img.spec().height, 3, OIIO::TypeDesc::UINT8));
  OIIO::ImageBufAlgo::clamp(out, img, 0.0f, 1.0f);
  out.specmod().attribute("ImageDescription", description);
  std::error_code ec;
  if (!out.write(tmp.string(), OIIO::TypeDesc::UINT8)) {
    fs::remove(tmp, ec);
    throw InputError("cannot write '" + path + "': " + out.geterror());
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw InputError("cannot write '" + path + "': " + ec.message());
  }
}

}  // namespace sf::eval::draw

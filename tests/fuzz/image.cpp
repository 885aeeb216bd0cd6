// Images as the filter reads them (read_raw: regular file, declared size against the budget and
// the file's size, pixels read and checked): a shadow map, a receiver image, receiver depth of
// the map's size, an environment map. The file's extension follows its magic bytes, so
// OpenImageIO tries that format's reader first.
#include <cstring>

#include "envmap.hpp"
#include "fuzz_support.hpp"
#include "image_io.hpp"
#include "io_detail.hpp"

namespace {

const char* extension_of(const uint8_t* data, size_t size) {
  auto starts = [&](const char* magic, size_t n) { return size >= n && std::memcmp(data, magic, n) == 0; };
  if (starts("v/1\x01", 4)) return ".exr";
  if (starts("\x89PNG", 4)) return ".png";
  if (starts("#?", 2)) return ".hdr";
  if (starts("II*\0", 4) || starts("MM\0*", 4)) return ".tif";
  if (starts("P", 1)) return ".pfm";  // OpenImageIO's PNM reader takes P1-P6, PF and Pf
  return ".exr";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  const std::string path = sf::fuzz::write_input(data, size, std::string("image") + extension_of(data, size));
  // The four readers share read_raw: an input it refuses is refused by each of them alike, and
  // reading it once keeps the harness fast (each OpenImageIO read costs a 64 MB buffer under ASan).
  try {
    sf::io::detail::read_raw(path, "image");
  } catch (const sf::InputError&) {
    return 0;
  }
  sf::HostImage depth;
  sf::fuzz::refusals_allowed([&] { depth = sf::io::load_depth_map(path, {}); });
  sf::fuzz::refusals_allowed([&] { sf::io::load_receiver_image(path); });
  sf::fuzz::refusals_allowed([&] {
    sf::io::load_receiver_depth(path, depth.width > 0 ? depth.width : 1, depth.height > 0 ? depth.height : 1, {});
  });
  sf::fuzz::refusals_allowed([&] { sf::scene::load_envmap(path); });
  return 0;
}

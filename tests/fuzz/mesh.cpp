// Mesh files as `scene` and `coherent build` read them (read_mesh_file: assimp, then finite
// vertices and faces within the vertices). The extension follows the content, so assimp picks
// that format's importer: PLY, OFF, STL (text, or binary of the size its count gives), else OBJ.
#include <cstring>

#include "fuzz_support.hpp"
#include "mesh_file.hpp"

namespace {

const char* extension_of(const uint8_t* data, size_t size) {
  auto starts = [&](const char* magic, size_t n) { return size >= n && std::memcmp(data, magic, n) == 0; };
  if (starts("ply", 3)) return ".ply";
  if (starts("OFF", 3) || starts("COFF", 4) || starts("NOFF", 4)) return ".off";
  if (starts("solid", 5)) return ".stl";
  if (size >= 84) {
    uint32_t triangles = 0;
    std::memcpy(&triangles, data + 80, 4);
    if (size == 84 + 50 * uint64_t(triangles)) return ".stl";
  }
  return ".obj";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  const std::string path = sf::fuzz::write_input(data, size, std::string("mesh") + extension_of(data, size));
  sf::fuzz::refusals_allowed([&] { sf::scene::read_mesh_file(path); });
  return 0;
}

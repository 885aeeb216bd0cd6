// Layered maps on disk (cascade_io.cpp): a layer file with its header (world_to_map, split,
// layer, blend) as a one-layer set, and a view file with its named channels.
#include "cascade_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  const std::string path = sf::fuzz::write_input(data, size, "layer.exr");
  sf::fuzz::refusals_allowed([&] { sf::io::load_cascade_set({path}); });
  sf::fuzz::refusals_allowed([&] { sf::io::load_view_receivers(path); });
  return 0;
}

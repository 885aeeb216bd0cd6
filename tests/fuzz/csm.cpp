// The coherent shadow map file (.csm): header, sizes, CRC, offsets and segments.
#include "coherent_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  const std::string path = sf::fuzz::write_input(data, size, "stack.csm");
  sf::fuzz::refusals_allowed([&] { sf::io::read_coherent(path); });
  return 0;
}

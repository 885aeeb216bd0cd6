// Camera and light files (camera_io.cpp): JSON, its keys, matrices and the projection checks.
#include <string>

#include "camera_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  const std::string text(reinterpret_cast<const char*>(data), size);
  sf::fuzz::refusals_allowed([&] { sf::io::parse_view_file(text, "camera 'fuzz.json'"); });
  return 0;
}

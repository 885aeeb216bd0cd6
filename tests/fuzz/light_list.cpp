// Light lists (`soft --lights`): files, weight= and size= values, bounds.
#include <sstream>

#include "fuzz_support.hpp"
#include "light_list.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  sf::fuzz::refusals_allowed([&] { sf::cli::parse_light_list(in, "fuzz/lights.txt"); });
  return 0;
}

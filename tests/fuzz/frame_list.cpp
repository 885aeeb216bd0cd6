// Frame lists (`filter --frames`, `soft --frames`): fields, quotes, comments, bounds, and the
// check that no frame writes another's input.
#include <sstream>

#include "frame_list.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sf::fuzz::setup();
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  sf::fuzz::refusals_allowed([&] {
    const std::vector<sf::cli::FrameSpec> frames = sf::cli::parse_frame_list(in, "fuzz/frames.txt");
    sf::cli::check_batch_outputs(frames, {}, "fuzz/frames.txt");
  });
  return 0;
}

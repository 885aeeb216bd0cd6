#pragma once
// The inputs of a layered run, `filter --cascades` and `soft --cascades`: a cascade set's layer
// files and the camera view they are read from (cascade_io.hpp), loaded once for both commands.
#include <string>
#include <vector>

#include "cascade_io.hpp"
#include "shadowfilter/cascades.hpp"

namespace sf::cli {

struct LayeredInputs {
  std::vector<std::string> files;  // the layer files, layer 0 first
  io::LayeredMaps layered;         // the set (blend as given) and its depth maps
  ViewReceivers view;
};

// InputError "--cascades cannot be combined with OPTION" when `given`: what a layered run
// cannot take, in both commands' words.
void refuse_with_cascades(bool given, const std::string& option);

// Checks that no output is an input (io::check_outputs), then reads the set of `cascades` (a
// directory or a comma-separated list, io::cascade_files) and the view file `view`. `blend`
// replaces the headers' blend band unless NaN; it must lie in [0, 1). InputError otherwise.
LayeredInputs load_layered_inputs(const std::string& cascades, const std::string& view, double blend,
                                  const std::vector<std::string>& outputs);

}  // namespace sf::cli

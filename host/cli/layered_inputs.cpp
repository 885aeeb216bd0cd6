// Loading a layered run's inputs (layered_inputs.hpp).
#include "layered_inputs.hpp"

#include <cmath>

#include "output_file.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {

void refuse_with_cascades(bool given, const std::string& option) {
  if (given) throw InputError("--cascades cannot be combined with " + option);
}

LayeredInputs load_layered_inputs(const std::string& cascades, const std::string& view, double blend,
                                  const std::vector<std::string>& outputs) {
  if (!std::isnan(blend) && !(blend >= 0.0 && blend < 1.0))
    throw InputError("--cascade-blend must lie in [0, 1), got " + std::to_string(blend));
  LayeredInputs in;
  in.files = io::cascade_files(cascades);
  std::vector<std::string> inputs = in.files;
  inputs.push_back(view);
  io::check_outputs(outputs, inputs);
  in.layered = io::load_cascade_set(in.files);
  if (!std::isnan(blend)) in.layered.set.blend = blend;
  validate(in.layered.set);
  in.view = io::load_view_receivers(view);
  return in;
}

}  // namespace sf::cli

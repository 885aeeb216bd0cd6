#pragma once
// The method registry. A method is a basis: its OpenCL header (kernels/methods/NAME.clh, which
// defines SF_CHANNELS, sf_method_params, sf_basis and sf_visibility), its channel count, and
// how its options pack into sf_method_params. Filters and lookups never see more than this.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "shadowfilter/options.hpp"

namespace sf {

struct MethodDesc {
  std::string name;
  std::string summary;
  std::string header;  // embedded kernel file
  int channels = 1;    // basis planes
  std::string parameters;  // one line: CLI parameters and their defaults
  // Checks the options against the method's limits; throws InputError naming the limit.
  std::function<void(const FilterOptions&)> validate;
  // The bytes of sf_method_params for these options (passed by value to the kernels).
  std::function<std::vector<uint8_t>(const FilterOptions&)> pack_params;
};

const std::vector<MethodDesc>& methods();
// Throws InputError listing the known names.
const MethodDesc& find_method(const std::string& name);

}  // namespace sf

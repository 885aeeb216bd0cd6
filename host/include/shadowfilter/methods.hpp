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
  std::string header;  // embedded kernel file ("" for raw-depth methods)
  // Basis planes for these options (csm: 2M); raw-depth methods: 1, the depth itself.
  std::function<int(const FilterOptions&)> channel_count;
  int channels(const FilterOptions& o) const { return channel_count(o); }
  std::string parameters;  // one line: CLI parameters and their defaults
  std::string storages;    // the storage formats it accepts, e.g. "f32 f16 unorm16 unorm8"
  // sm and pcf test the depth map itself (kernels/pcf.cl): no basis transform and no prefilter;
  // the reconstruction evaluates H(z - d + b) per texel under the lookup's weights.
  bool raw_depth = false;
  // Extra program build options for these options (e.g. -DSF_CSM_ORDER=8).
  std::function<std::string(const FilterOptions&)> defines;
  // Checks the options against the method's limits; throws InputError naming the limit.
  std::function<void(const FilterOptions&)> validate;
  // The bytes of sf_method_params for these options (passed by value to the kernels).
  std::function<std::vector<uint8_t>(const FilterOptions&)> pack_params;
};

const std::vector<MethodDesc>& methods();
// Bytes of basis images per shadow-map texel for these options (channels x storage bytes).
size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o);
// The depth bias in effect: FilterOptions::depth_test.bias, else the method's default.
float depth_bias(const FilterOptions& o);

// The csm reconstruction parameters for these options (defaults resolved per order).
struct CsmParameters {
  float alpha = 0, offset = 0, scale = 1;
};
CsmParameters csm_parameters(const FilterOptions& o);

// Throws InputError listing the known names.
const MethodDesc& find_method(const std::string& name);

}  // namespace sf

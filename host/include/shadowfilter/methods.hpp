#pragma once
// The method registry: the one place that knows methods. A method is its OpenCL header
// (kernels/methods/NAME.clh, defining SF_CHANNELS, sf_method_params, sf_basis and
// sf_visibility) and one registration (host/src/methods/NAME.cpp): its channel count, its
// storages and their limits, its parameters with their defaults, its double-precision twin
// (the scalar reference's half of the method), the variants evaluate and --auto try, its cost
// coefficients and its labels. Filters, lookups, the pipeline, the reference, evaluate and the
// CLI ask this record and never test a method's name.
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "shadowfilter/options.hpp"
#include "shadowfilter/sat_precision.hpp"

namespace sf {

// The method's math in double: basis values as the kernel stores them before rounding (mapped
// into [0,1] where the method does so for unorm storage), and the visibility from filtered
// stored values, clamped to [0,1]. Same parameters as the kernel (defaults and clamps resolved).
struct ScalarMethod {
  int channels = 1;
  std::function<void(double z, double* b)> basis;
  std::function<double(const double* b, double d)> visibility;
};

// A storage format a method accepts, and what it bounds.
struct StorageLimit {
  Storage storage = Storage::F32;
  std::string limit;  // one line for `shadowfilter methods`; "" when nothing beyond the method's own
  // Brings options into this storage's limits where a grid or table varies the storage (esm in
  // f16: c = 20); empty when every valid option fits.
  std::function<void(FilterOptions&)> fit;
};

// Which parameter variants a caller wants: evaluate's grids, and --auto's candidates.
enum class GridSize { Quick, Default, Wide, Auto };

// --auto's cost estimate in nanoseconds (coefficients measured on PoCL, docs/results.md
// "cost model"): per map texel, transform_per_channel x channels; per receiver, reconstruct +
// reconstruct_per_channel x channels + per_support_texel x (2R + 2)^2.
struct CostModel {
  double transform_per_channel = 0.5;
  double reconstruct = 9.0;
  double reconstruct_per_channel = 0.0;
  double per_support_texel = 0.0;
};

// One named parameter value, as summaries and result files show it ("c" 80).
struct MethodParameter {
  std::string key;
  double value = 0;
};

struct MethodDesc {
  std::string name;
  std::string summary;
  std::string header;  // embedded kernel file ("" for raw-depth methods)
  // Basis planes for these options (csm: 2M); raw-depth methods: 1, the depth itself.
  std::function<int(const FilterOptions&)> channel_count;
  int channels(const FilterOptions& o) const { return channel_count(o); }
  std::string channels_note;  // how the channel count varies ("2M", "" when fixed), for summaries
  // Whether the channel count follows the method's order (FilterOptions::csm.order): test and
  // bench cases walk the orders, --auto notes when smaller orders miss the bound.
  bool order_sets_channels = false;
  std::string parameters;  // one line: CLI parameters and their defaults
  std::vector<StorageLimit> storages;
  // sm and pcf test the depth map itself (kernels/pcf.cl): no basis transform and no prefilter;
  // the reconstruction evaluates H(z - d + b) per texel under the lookup's weights.
  bool raw_depth = false;
  // Whether the result follows the prefilter's radius and the lookup's footprints (sm: no, it
  // is the unfiltered test).
  bool filtered = true;
  // Whether FilterOptions::esm_classify may flag its failures (the classification stage,
  // classify.hpp, reads this method's basis).
  bool classifiable = false;
  // Extra program build options for these options (e.g. -DSF_CSM_ORDER=8).
  std::function<std::string(const FilterOptions&)> defines;
  // Checks the options against the method's limits; throws InputError naming the limit.
  std::function<void(const FilterOptions&)> validate;
  // Where the summed-area table (Lookup::Sat) cannot hold this method's basis on `map` within the
  // documented error (sat_precision.hpp): a one-line refusal naming the limit and what to use
  // instead; "" where it can. Empty for bases that need none.
  std::function<std::string(const FilterOptions&, const SatMap& map)> sat_limit;
  // The bytes of sf_method_params for these options (passed by value to the kernels).
  std::function<std::vector<uint8_t>(const FilterOptions&)> pack_params;
  // The depth bias when FilterOptions::depth_test.bias is unset.
  std::function<float(const FilterOptions&)> default_depth_bias = [](const FilterOptions&) { return 0.0f; };
  // The double-precision twin of the kernel header for these options (raw-depth methods: none,
  // the reference tests the depth itself).
  std::function<ScalarMethod(const FilterOptions&)> scalar;
  // Every parameter in effect, defaults resolved (summaries, result files).
  std::function<std::vector<MethodParameter>(const FilterOptions&)> parameter_values;
  // The short label of evaluate's rows: the parameters a grid varies (" c=80").
  std::function<std::string(const FilterOptions&)> label;
  // Parameter variants of `base` for a grid (each then crossed with radii, lookups, storages).
  std::function<std::vector<FilterOptions>(const FilterOptions& base, GridSize)> variants;
  bool quick_footprints = false;  // the quick grid also tries the footprint lookups
  CostModel cost;
  std::array<float, 3> colour{0.3f, 0.3f, 0.3f};  // plot colour (fixed: every plot reads the same)

  bool accepts(Storage s) const;
  std::string storage_list() const;                    // "f32 f16"
  const StorageLimit& storage_limit(Storage s) const;  // throws InputError when not accepted
  // o with the storage's fit applied (o.storage must be accepted).
  FilterOptions fitted(FilterOptions o) const;
};

const std::vector<MethodDesc>& methods();
// The method's sat_limit for these options on `map` ("" when the lookup is not sat or the
// method has no limit there).
std::string sat_refusal(const FilterOptions& o, const SatMap& map);
// Bytes of basis images per shadow-map texel for these options (channels x storage bytes).
size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o);
// The depth bias in effect: FilterOptions::depth_test.bias, else the method's default.
float depth_bias(const FilterOptions& o);
// The classification in effect: FilterOptions::esm_classify.mode, Auto resolved (zmax for a
// classifiable method, none for the others).
EsmClassify classify_mode(const FilterOptions& o);

// The csm reconstruction parameters for these options (defaults resolved per order).
struct CsmParameters {
  float alpha = 0, offset = 0, scale = 1;
};
CsmParameters csm_parameters(const FilterOptions& o);

// Throws InputError listing the known names.
const MethodDesc& find_method(const std::string& name);

}  // namespace sf

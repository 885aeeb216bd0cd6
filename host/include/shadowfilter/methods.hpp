#pragma once
// The method registry: the one place that knows methods. A method is its OpenCL header
// (kernels/methods/NAME.clh, defining SF_CHANNELS, sf_method_params, sf_basis and
// sf_visibility) and one registration (host/src/methods/NAME.cpp): its channel count, its
// storages and their limits, its parameters with their defaults, its double-precision twin
// (the scalar reference's half of the method). Filters, lookups, the pipeline, the reference,
// evaluate and the CLI ask this record and never test a method's name. What evaluate and --auto
// know of a method (plot colour, row labels, grid variants, cost model) is evaluate's catalogue
// (host/eval/method_catalogue.hpp), not the core's.
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "shadowfilter/options.hpp"
#include "shadowfilter/parameters.hpp"
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

// One named parameter value, as summaries and result files show it ("c" 80).
struct MethodParameter {
  std::string key;
  double value = 0;
};

struct MethodDesc {
  std::string name;
  std::string summary;
  std::string header;  // kernel file ("" for raw-depth methods): embedded (kernels/), or header_source
  // The header's OpenCL source where the method brings its own (sf::register_method from outside
  // the library); "" for the embedded headers. Runtime::program() finds it by `header`.
  std::string header_source;
  // Basis planes for these options (csm: 2M); raw-depth methods: 1, the depth itself.
  std::function<int(const FilterOptions&)> channel_count;
  int channels(const FilterOptions& o) const { return channel_count(o); }
  std::string channels_note;  // how the channel count varies ("2M", "" when fixed), for summaries
  // Whether the channel count follows the method's order (FilterOptions::csm.order): test and
  // bench cases walk the orders, --auto notes when smaller orders miss the bound.
  bool order_sets_channels = false;
  // The method's own parameters, each declared once (parameters.hpp). A parameter several methods
  // share (vsm's and evsm's --lbr) is the same declaration in each.
  std::vector<Parameter> parameters;
  // The FilterOptions-wide knobs (filter_parameters()) the method also reads, by field, for
  // `shadowfilter methods` ("FilterOptions::depth_test.bias").
  std::vector<std::string> reads;
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
  // The normal offset in texels when FilterOptions::normal_offset is unset (normal_offset.hpp):
  // measured where it lowers leaks at no cost in RMSE (docs/results.md "Normal offset"), else 0.
  float default_normal_offset = 0.0f;
  // The double-precision twin of the kernel header for these options (raw-depth methods: none,
  // the reference tests the depth itself).
  std::function<ScalarMethod(const FilterOptions&)> scalar;
  // Every parameter in effect, defaults resolved (summaries, result files).
  std::function<std::vector<MethodParameter>(const FilterOptions&)> parameter_values;

  bool accepts(Storage s) const;
  std::string storage_list() const;                    // "f32 f16"
  const StorageLimit& storage_limit(Storage s) const;  // throws InputError when not accepted
  // o with the storage's fit applied (o.storage must be accepted).
  FilterOptions fitted(FilterOptions o) const;
};

// The registered methods in registration order: the library's own, then those added by
// register_method (a deque: a registration's address never changes, handles stay valid).
const std::deque<MethodDesc>& methods();

// Adds a method to the registry and returns its handle. For methods defined outside the library
// (a renderer's own, a test's): `header_source` holds its OpenCL header (SF_CHANNELS,
// sf_method_params, sf_basis, sf_basisv, sf_visibility; kernels/methods/*.clh are the models)
// and its parameters keep their values in FilterOptions::parameters (Parameter::stored). Throws
// InputError for a name already registered, a header that is neither embedded nor given, a
// missing function (channel_count, validate, pack_params, scalar, parameter_values), or a
// parameter whose field or flag another declaration uses differently. Register before any
// other thread reads the registry (the registry is not locked against concurrent readers).
Method register_method(MethodDesc desc);

// The method of this name (the boundary: CLI, files, bindings); InputError listing the known
// names for any other.
Method method(const std::string& name);

// Every check of `o` a plan makes, once: finite fields (require_finite_options), the method's
// declared parameter ranges (check_parameters) and the method's own validation.
void validate_options(const FilterOptions& o);
// The method's sat_limit for these options on `map` ("" when the lookup is not sat or the
// method has no limit there).
std::string sat_refusal(const FilterOptions& o, const SatMap& map);
// Bytes of basis images per shadow-map texel for these options (channels x storage bytes).
size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o);
// The depth bias in effect: FilterOptions::depth_test.bias, else the method's default.
float depth_bias(const FilterOptions& o);
// The normal offset in effect: FilterOptions::normal_offset, else the method's default.
float normal_offset(const FilterOptions& o);
// The classification in effect: FilterOptions::esm_classify.mode, Auto resolved (zmax for a
// classifiable method, none for the others).
EsmClassify classify_mode(const FilterOptions& o);

// The csm reconstruction parameters for these options (defaults resolved per order).
struct CsmParameters {
  float alpha = 0, offset = 0, scale = 1;
};
CsmParameters csm_parameters(const FilterOptions& o);

}  // namespace sf

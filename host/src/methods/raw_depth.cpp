// sm and pcf: the depth tests on the depth map itself (kernels/pcf.cl). Their reference is the
// depth test (host/reference/methods_pcf.cpp), which needs no basis.
#include "registration.hpp"

namespace sf::registration {

MethodDesc raw_depth_method(const std::string& name, const std::string& summary, bool filtered) {
  MethodDesc m;
  m.name = name;
  m.summary = summary;
  m.raw_depth = true;
  m.filtered = filtered;
  m.channel_count = [](const FilterOptions&) { return 1; };
  m.parameters = "--bias B (default 0)";
  m.storages = plain_storages({Storage::F32});
  m.validate = [m](const FilterOptions& o) {
    require_finite(depth_bias(o), "FilterOptions::depth_test.bias");
    check_storage(m, o, "it tests the float32 depth map itself and has no basis images");
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(depth_bias(o)); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.parameter_values = [](const FilterOptions& o) { return std::vector<MethodParameter>{{"bias", depth_bias(o)}}; };
  m.label = [](const FilterOptions&) { return std::string(); };
  m.variants = [](const FilterOptions& base, GridSize) { return std::vector<FilterOptions>{base}; };
  // sm: one fetch and test per bilinear tap; pcf: every texel of the (2R + 2)^2 support.
  m.cost = filtered ? CostModel{0.0, 8.0, 0.0, 1.2} : CostModel{0.0, 9.0, 0.0, 0.0};
  m.colour = filtered ? std::array<float, 3>{0.55f, 0.55f, 0.55f} : std::array<float, 3>{0.0f, 0.0f, 0.0f};
  return m;
}

}  // namespace sf::registration

// sm and pcf: the depth tests on the depth map itself (kernels/pcf.cl). Their reference is the
// depth test (host/reference/methods_pcf.cpp), which needs no basis.
#include "plane_params.hpp"
#include "registration.hpp"

namespace sf::registration {

namespace {
// The default bias against the receiver plane, measured (docs/results.md "Defaults sweep"): the
// plane removes the depth change across a tilted receiver's support, what is left is the
// curvature and faceting of real surfaces and the plane's error where its gradient comes from
// neighbours texels away; 0.003 of the depth range keeps acne below 0.5% on every built-in scene
// and the scanned bunny at 512 and 2048 maps, with the fewest leaks (the tie bias 2^-15 alone
// leaves 1-4% acne). Without the plane the test is s_ref of the constant d (bias 0).
constexpr float kPlaneBias = 0.003f;
}  // namespace

MethodDesc raw_depth_method(const std::string& name, const std::string& summary, bool filtered) {
  MethodDesc m;
  // sm looks up half a texel along the receiver's normal (docs/results.md "Normal offset": terrain's
  // umbra leak 3.9% -> 2.0% at 512, acne 0.29% -> 0.06%, at the same bias, so receivers without
  // normals test as before); pcf none (with the plane, 0.5 and 1 leak 0.96% on the scanned bunny
  // at 512, from 0.48%).
  m.default_normal_offset = filtered ? 0.0f : 0.5f;
  m.name = name;
  m.summary = summary;
  m.raw_depth = true;
  m.filtered = filtered;
  m.channel_count = [](const FilterOptions&) { return 1; };
  m.reads = {"FilterOptions::depth_test.bias", "FilterOptions::receiver_plane.enabled",
             "FilterOptions::receiver_plane.slope_bias"};
  m.storages = plain_storages({Storage::F32});
  m.validate = [m](const FilterOptions& o) {
    require_finite(depth_bias(o), "FilterOptions::depth_test.bias");
    detail::validate(o.receiver_plane, "FilterOptions::receiver_plane");
    check_storage(m, o, "it tests the float32 depth map itself and has no basis images");
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(depth_bias(o)); };
  // Without the plane the test is s_ref of the constant d (bias 0), with it the plane's tie bias.
  m.default_depth_bias = [](const FilterOptions& o) { return o.receiver_plane.enabled ? kPlaneBias : 0.0f; };
  m.defines = [](const FilterOptions&) { return std::string(); };
  m.parameter_values = [](const FilterOptions& o) {
    return std::vector<MethodParameter>{{"bias", depth_bias(o)},
                                        {"slope_bias", o.receiver_plane.enabled ? o.receiver_plane.slope_bias : 0.0f}};
  };
  return m;
}

}  // namespace sf::registration

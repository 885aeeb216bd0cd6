// The structs of kernels/shared_types.clh, compiled as C++ here and as OpenCL C on the device,
// must agree byte for byte: a probe kernel writes each struct's size and every member's offset as
// the device compiler lays them out, and they are compared with the host's.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "sf_test_env.hpp"
#include "shadowfilter/runtime.hpp"
#include "shared_types.clh"

namespace sf {
namespace {

struct Member {
  std::string name;
  int offset;
};
struct Layout {
  std::string type;
  int size;
  std::vector<Member> members;
};
#define SF_MEMBER(T, m) \
  Member { #m, int(offsetof(T, m)) }
#define SF_LAYOUT(T, ...)               \
  Layout {                              \
#T, int(sizeof(T)), { __VA_ARGS__ } \
  }

const std::vector<Layout>& host_layouts() {
  static const std::vector<Layout> all = {
      SF_LAYOUT(sf_esm_params, SF_MEMBER(sf_esm_params, c)),
      SF_LAYOUT(sf_vsm_params, SF_MEMBER(sf_vsm_params, min_variance), SF_MEMBER(sf_vsm_params, lbr)),
      SF_LAYOUT(sf_evsm_params, SF_MEMBER(sf_evsm_params, pos), SF_MEMBER(sf_evsm_params, neg),
                SF_MEMBER(sf_evsm_params, min_variance), SF_MEMBER(sf_evsm_params, lbr)),
      SF_LAYOUT(sf_msm_params, SF_MEMBER(sf_msm_params, moment_bias), SF_MEMBER(sf_msm_params, depth_bias)),
      SF_LAYOUT(sf_csm_params, SF_MEMBER(sf_csm_params, alpha), SF_MEMBER(sf_csm_params, offset),
                SF_MEMBER(sf_csm_params, scale)),
      SF_LAYOUT(sf_pcf_weights, SF_MEMBER(sf_pcf_weights, w)),
      SF_LAYOUT(sf_plane_params, SF_MEMBER(sf_plane_params, on), SF_MEMBER(sf_plane_params, row),
                SF_MEMBER(sf_plane_params, max_slope), SF_MEMBER(sf_plane_params, slope_bias)),
      SF_LAYOUT(sf_classify_params, SF_MEMBER(sf_classify_params, mode), SF_MEMBER(sf_classify_params, offset),
                SF_MEMBER(sf_classify_params, log_thresh), SF_MEMBER(sf_classify_params, top),
                SF_MEMBER(sf_classify_params, zoff)),
      SF_LAYOUT(sf_soft_light, SF_MEMBER(sf_soft_light, ku), SF_MEMBER(sf_soft_light, kv), SF_MEMBER(sf_soft_light, a),
                SF_MEMBER(sf_soft_light, b), SF_MEMBER(sf_soft_light, persp), SF_MEMBER(sf_soft_light, bias),
                SF_MEMBER(sf_soft_light, max_width)),
      SF_LAYOUT(sf_cssm_params, SF_MEMBER(sf_cssm_params, offset), SF_MEMBER(sf_cssm_params, scale),
                SF_MEMBER(sf_cssm_params, sharpen_a), SF_MEMBER(sf_cssm_params, sharpen_b),
                SF_MEMBER(sf_cssm_params, min_den), SF_MEMBER(sf_cssm_params, z_offset),
                SF_MEMBER(sf_cssm_params, width_scale), SF_MEMBER(sf_cssm_params, inv_lit),
                SF_MEMBER(sf_cssm_params, contact)),
      SF_LAYOUT(sf_cascade_params, SF_MEMBER(sf_cascade_params, m), SF_MEMBER(sf_cascade_params, split_near),
                SF_MEMBER(sf_cascade_params, split_far), SF_MEMBER(sf_cascade_params, count),
                SF_MEMBER(sf_cascade_params, width), SF_MEMBER(sf_cascade_params, height),
                SF_MEMBER(sf_cascade_params, blend)),
  };
  return all;
}

// The probe: for each struct, its size and then each member's offset, as the device lays it out.
std::string probe_source(const std::vector<Layout>& layouts) {
  std::string s =
      kernel_source("shared_types.clh") + "\n__kernel void sf_layout_probe(__global int* out) {\n  int n = 0;\n";
  for (const Layout& l : layouts) {
    s += "  { " + l.type + " p; out[n++] = (int)sizeof(" + l.type + ");\n";
    for (const Member& m : l.members)
      s += "    out[n++] = (int)((__private char*)&p." + m.name + " - (__private char*)&p);\n";
    s += "  }\n";
  }
  return s + "}\n";
}

TEST(SharedTypes, HostAndDeviceAgreeOnEveryStructLayout) {
  const auto& layouts = host_layouts();
  size_t count = 0;
  for (const Layout& l : layouts) count += 1 + l.members.size();
  Runtime& rt = test::runtime();
  cl::Program p(rt.context(), probe_source(layouts));
  p.build({rt.device()}, "-cl-std=CL1.2");
  cl::Kernel k(p, "sf_layout_probe");
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, count * sizeof(cl_int));
  k.setArg(0, out);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NullRange);
  std::vector<cl_int> device(count);
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, count * sizeof(cl_int), device.data());
  size_t i = 0;
  for (const Layout& l : layouts) {
    EXPECT_EQ(device[i++], l.size) << "sizeof(" << l.type << ")";
    for (const Member& m : l.members) EXPECT_EQ(device[i++], m.offset) << l.type << "::" << m.name;
  }
  // Every member is 4 bytes wide and the structs have no padding (shared_types.clh's rule).
  EXPECT_EQ(sizeof(sf_pcf_weights), (SF_PCF_MAX_RADIUS + 1) * sizeof(float));
  EXPECT_EQ(sizeof(sf_cssm_params), 9 * 4u);
}

}  // namespace
}  // namespace sf

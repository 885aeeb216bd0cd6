#pragma once
// Soft shadows from square area lights (methods.md sec. 4; docs/soft.md): pcss (brute force),
// cssm (convolution soft shadows, Annen 2008 ch. 8), ssmm and ssmm-improved (soft shadow mip-maps,
// Shen 2016). They read the raw depth (or their own bases and pyramids / SATs) and output
// visibility per receiver, like the basis methods at the reconstruction end.
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/pipeline.hpp"

namespace sf {

enum class SoftMethod { Pcss, Cssm, Ssmm, SsmmImproved };
const char* soft_method_name(SoftMethod m);                   // "pcss", "cssm", "ssmm", "ssmm-improved"
bool parse_soft_method(const std::string& s, SoftMethod* m);  // false for other names

// The light (scene generator conventions, docs/scenes.md). Depth d in [0,1] is the linear light
// depth; view depth = near + d (far - near).
struct SoftLight {
  bool perspective = false;
  double size = 0.1;        // width of the square light, light-space (world) units
  double near_plane = 0.0;  // view depths of d = 0 and d = 1
  double far_plane = 1.0;
  double extent = 1.0;       // orthographic: width of the map in light-space units
  double fov_degrees = 0.0;  // perspective: full field of view of the (square) map
  double weight = 1.0;       // several lights: visibilities are combined by weight
};
// Width (uv units) of the light's footprint in the plane of a blocker at depth z, seen from a
// receiver at depth d (soft_common.clh): ortho (L/extent)(D_R - D_B)/D_R; perspective
// L/(2 tan(fov/2)) (D_R - D_B)/(D_R D_B), D = distance from the light along its axis.
double soft_width(const SoftLight& light, double d, double z);

struct SoftOptions {
  SoftMethod method = SoftMethod::Pcss;
  SoftLight light;
  // pcss and ssmm test each texel against the receiver's plane d_t (docs/receiver_plane.md), with
  // the plane's slope-scaled bias on top of `bias`; cssm reconstructs from a basis and has none.
  // Both measured (docs/results.md "Defaults sweep"): 0.005 and a quarter texel of the plane's
  // slope, the lowest worst RMSE against the ray-traced soft shadows with acne below 0.5%.
  float bias = 5e-3f;  // a texel z blocks a receiver d when z < d_t - bias
  ReceiverPlaneOptions receiver_plane{true, 0.1f, 0.25f};
  bool facing_away_shadowed = true;  // receivers with ndl <= 0: 0 (sf::shadow_facing_away)
  float max_width = 256.0f;          // cap of every kernel width, level-0 texels
  // cssm (defaults chosen on the bundled scenes, docs/soft.md "cssm defaults"; the offset and
  // scale by the defaults sweep, docs/results.md). Negative values select the default, which
  // depends on M.
  int cssm_order = 4;                // M: 4M + 1 basis planes
  Lookup cssm_lookup = Lookup::Sat;  // mips or sat
  float cssm_offset = -1.0f;         // stage 2 reads the series at d' = d - offset; default 0.2 / M
  float cssm_scale = -1.0f;          // v = clamp(0.5 + scale (s_f - 0.5), 0, 1); default 1.5
  float cssm_width_scale = -1.0f;    // stage-2 kernel width multiplier; default scale lit (keeps penumbrae)
  bool cssm_normalise = false;       // use s_f / lit (lit = the series of a lit texel, z = d, at d')
  float cssm_sharpen_a = 30.0f;      // eq. 8.9: p = 1 + A exp(-B (d - z_avg)); A = 0: off
  float cssm_sharpen_b = -1.0f;      // default 10 M
  float cssm_min_den = 0.02f;        // 1 - s_f below this: no blocker farther than z_offset
  float cssm_z_offset = -1.0f;       // stage-1 (z_avg) offset; default ~0.306 / M (series = 1 at z = d)
  bool cssm_contact = true;          // no blocker in stage 1: still run stage 2 at the footprint (z_avg = d)
  // ssmm
  int ssmm_n = 4;  // n x n texels per layer (Shen 2016 eq. 3.4)
};
void validate(const SoftOptions& opt);  // throws InputError
// cssm's parameters in effect (defaults resolved).
struct CssmParams {
  float offset, z_offset, scale, width_scale, lit, sharpen_a, sharpen_b;
};
CssmParams cssm_params(const SoftOptions& opt);
// The truncated series 1/2 + 2 sum_k sin(c_k x) / c_k of order M at x = z - d' (1 - it is the
// blocker weight); lit = cssm_series(M, offset).
double cssm_series(int order, double x);
float cssm_z_offset(const SoftOptions& opt);  // offset of the z_avg stage in effect

struct SoftTimes {  // device seconds (profiling queues), 0 otherwise
  double transform = 0, pyramid = 0, sat = 0, reconstruct = 0;
  double total() const { return transform + pyramid + sat + reconstruct; }
};

// One light's shadow map on the device. prepare() builds what the method reads (cssm: basis +
// mips or SAT; ssmm: min-depth pyramid); run() writes visibility of `count` receivers.
class SoftFilter {
 public:
  SoftFilter(std::shared_ptr<Runtime> rt, SoftOptions opt, int width, int height);
  cl::Event prepare(const cl::Buffer& depth, const EventList* wait = nullptr);
  // f may be an empty buffer (footprint 1); zavg (cssm only, may be empty): z_avg per receiver
  // (NaN where no blocker was found).
  // receiver_row: receivers per row of the receiver image, whose neighbours give each receiver's
  // plane (DeviceReceivers::row); 0 = unstructured points.
  cl::Event run(const cl::Buffer& u, const cl::Buffer& v, const cl::Buffer& d, const cl::Buffer& f,
                const cl::Buffer& visibility, size_t count, const EventList* wait = nullptr,
                const cl::Buffer* zavg = nullptr, int receiver_row = 0);
  SoftTimes times() const;
  const SoftOptions& options() const { return opt_; }

 private:
  std::shared_ptr<Runtime> rt_;
  SoftOptions opt_;
  int W_, H_;
  cl::Buffer depth_, basis_, chain_, sat_, bands_, packed_;  // packed_: cssm's interleaved SAT
  cl::Event transform_done_, run_done_, pack_done_;
  PassEvents pyr_done_, sat_done_;
  bool have_pyr_ = false, have_sat_ = false, have_transform_ = false;
};

// Host convenience: one light.
struct SoftResult {
  HostImage visibility;
  SoftTimes times;
  size_t background = 0, outside = 0;
};
SoftResult soft_filter(std::shared_ptr<Runtime> rt, const SoftOptions& opt, const HostImage& depth,
                       const Receivers& receivers);

// Several lights: each has its own shadow map and receivers (u, v, d in that light's map) of the
// same output size; v = sum_i weight_i v_i / sum_i weight_i.
struct SoftLightInput {
  SoftLight light;
  HostImage depth;
  Receivers receivers;
};
SoftResult soft_filter_lights(std::shared_ptr<Runtime> rt, const SoftOptions& opt,
                              const std::vector<SoftLightInput>& lights);

}  // namespace sf

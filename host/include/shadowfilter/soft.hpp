#pragma once
// Soft shadows from rectangular area lights (methods.md sec. 4; docs/soft.md): pcss (brute force),
// cssm (convolution soft shadows, Annen 2008 ch. 8), ssmm and ssmm-improved (soft shadow mip-maps,
// Shen 2016). They read the raw depth (or their own bases and pyramids / SATs) and output
// visibility per receiver, like the basis methods at the reconstruction end.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/view_projection.hpp"

namespace sf {

// A technique is selected by a resolved value in the options (SoftOptions::method here, the
// method of FilterOptions for hard shadows); names are looked up only at the boundary (CLI,
// files, bindings) by a find_* function that throws InputError naming the known ones.
enum class SoftMethod { Pcss, Cssm, Ssmm, SsmmImproved };
const char* soft_method_name(SoftMethod m);            // "pcss", "cssm", "ssmm", "ssmm-improved"
SoftMethod find_soft_method(const std::string& name);  // InputError for other names

// The light (scene generator conventions, docs/scenes.md). Depth d in [0,1] is the linear light
// depth; view depth = near + d (far - near).
struct SoftLight {
  bool perspective = false;
  double size = 0.1;        // side along the map's u axis (the light's right), world units
  double near_plane = 0.0;  // view depths of d = 0 and d = 1
  double far_plane = 1.0;
  double extent = 1.0;       // orthographic: width of the map in light-space units
  double fov_degrees = 0.0;  // perspective: full field of view of the (square) map
  double weight = 1.0;       // several lights: visibilities are combined by weight
  double height = -1.0;      // side along the map's v axis (the light's down); < 0: size (a square)
  // Orthographic: the distance along the light's axis from the area light to the map's plane
  // d = 0, in the units of near and far. 0: the light lies in that plane (where `scene` puts it);
  // a cascade layer's map starts wherever its slice does, so its light lies before it
  // (layer_soft_light, layered.hpp). Receivers and blockers at or before the light's plane are
  // outside the model: the kernels clamp the distance at 1e-20 (no footprint, and half the light
  // below a receiver's horizon). Perspective lights ignore it.
  double light_distance = 0.0;
};
double light_height(const SoftLight& light);  // the v side in effect: height >= 0 ? height : size
// The distance from the light along its axis of a map depth d, D = a + b d, in the units the
// footprints use (only their ratios matter): perspective a = near, b = far - near; orthographic
// a = light_distance / (far - near), b = 1. The kernels (sf_soft_light), the footprints below and
// the double reference all read it from here.
struct SoftDistance {
  double a = 0.0, b = 1.0;
};
SoftDistance soft_distance(const SoftLight& light);
// The footprint's scale k per unit of light side (soft_common.clh): ortho 1 / extent, perspective
// 1 / (2 tan(fov/2)); a side L covers k L g(d, z) in uv, with g as soft_width gives it.
double soft_side_scale(const SoftLight& light);
// Width (uv units) along u of the light's footprint in the plane of a blocker at depth z, seen
// from a receiver at depth d (soft_common.clh): ortho (L/extent)(D_R - D_B)/D_R; perspective
// L/(2 tan(fov/2)) (D_R - D_B)/(D_R D_B), D = distance from the light along its axis, L = size;
// soft_height: the same along v, L = light_height.
double soft_width(const SoftLight& light, double d, double z);
double soft_height(const SoftLight& light, double d, double z);
// The light of a light's view and projection (camera-file conventions, docs/inputs.md):
// orthographic with the map's width in light units 2 / |projection[0][0]|, or perspective with
// the full field of view 2 atan(1 / |projection[0][0]|) across the map's width; its planes from
// the projection (light_projection_depth); `size` x `height` the area light's sides in world units
// (height < 0: a square of side size). InputError for a projection light_projection_depth refuses
// and for sides not finite and >= 0.
SoftLight soft_light(const ViewProjection& light, double size, double height = -1.0);

// cssm (convolution soft shadows, Annen 2008 ch. 8). Defaults chosen on the bundled scenes
// (docs/soft.md "cssm defaults"; the offset and scale by the defaults sweep, docs/results.md).
// Negative values select the default, which depends on M.
struct CssmOptions {
  int order = 4;                // M: 4M + 1 basis planes
  Lookup lookup = Lookup::Sat;  // mips or sat
  float offset = -1.0f;         // stage 2 reads the series at d' = d - offset; default 0.2 / M
  float scale = -1.0f;          // v = clamp(0.5 + scale (s_f - 0.5), 0, 1); default 1.5
  float width_scale = -1.0f;    // stage-2 kernel width multiplier; default scale lit (keeps penumbrae)
  bool normalise = false;       // use s_f / lit (lit = the series of a lit texel, z = d, at d')
  float sharpen_a = 30.0f;      // eq. 8.9: p = 1 + A exp(-B (d - z_avg)); A = 0: off
  float sharpen_b = -1.0f;      // default 10 M
  float min_den = 0.02f;        // 1 - s_f below this: no blocker farther than z_offset
  float z_offset = -1.0f;       // stage-1 (z_avg) offset; default ~0.306 / M (series = 1 at z = d)
  bool contact = true;          // no blocker in stage 1: still run stage 2 at the footprint (z_avg = d)
  // The basis planes' storage (options.hpp; with mip-maps Annen 2008 sec. 8.4 stores the CSM
  // planes in 8 bits, the CSM-Z planes in 16).
  // f16 and unorm16 with mips only (the SAT's table is float-float whatever its input); unorm8
  // is refused: it moves the visibility 0.03-0.05 RMS from float32's (docs/soft.md).
  Storage storage = Storage::F32;
};

// ssmm and ssmm-improved (soft shadow mip-maps, Shen 2016).
struct SsmmOptions {
  int n = 4;  // n x n texels per layer (Shen 2016 eq. 3.4)
};

// Every knob of a soft-shadow run: the generic ones, then one struct per technique (as
// FilterOptions holds esm, vsm, ...); `method` selects the technique, the other structs are
// ignored. pcss has no knob of its own.
struct SoftOptions {
  SoftMethod method = SoftMethod::Pcss;
  SoftLight light;
  // pcss and ssmm test each texel against the receiver's plane d_t (docs/receiver_plane.md), with
  // the plane's slope-scaled bias on top of `bias`; cssm reconstructs from a basis and has none.
  // Both measured (docs/results.md "Defaults sweep", "Normal offset"): 0.005 and no slope term,
  // with their normal offset of half a texel; the slope term (a quarter texel before
  // the offset) let grazing receivers through behind terrain's crests (leak 6.7% -> 1.8%).
  float bias = 5e-3f;  // a texel z blocks a receiver d when z < d_t - bias
  ReceiverPlaneOptions receiver_plane{true, 0.1f, 0.0f};
  bool facing_away_shadowed = true;  // receivers with ndl <= 0: 0 (sf::shadow_facing_away)
  // Texels each lookup moves along the receiver's normal (FilterOptions::normal_offset); < 0:
  // the method's measured default (soft_normal_offset).
  float normal_offset = -1.0f;
  float max_width = 256.0f;  // cap of every kernel width, level-0 texels
  CssmOptions cssm;
  SsmmOptions ssmm;
};
void validate(const SoftOptions& opt);  // throws InputError
// The normal offset in effect: SoftOptions::normal_offset, else the method's measured default
// (pcss, ssmm, ssmm-improved: half a texel; cssm: none; docs/results.md "Normal offset").
float soft_normal_offset(const SoftOptions& opt);
// The SoftOptions fields validate() names in its messages, each with the command-line flag that
// sets it ("SoftOptions::cssm.order" -> "--cssm-order"): the CLI names its flags in messages and
// the Python binding its keywords (the flag's name with '_' for '-'), from this one table.
const std::vector<std::pair<std::string, std::string>>& soft_option_flags();
// cssm's parameters in effect (defaults resolved).
struct CssmParams {
  float offset, z_offset, scale, width_scale, lit, sharpen_a, sharpen_b;
};
CssmParams cssm_params(const SoftOptions& opt);
// The truncated series 1/2 + 2 sum_k sin(c_k x) / c_k of order M at x = z - d' (1 - it is the
// blocker weight); lit = cssm_series(M, offset).
double cssm_series(int order, double x);
float cssm_z_offset(const SoftOptions& opt);  // offset of the z_avg stage in effect

// One light's shadow map on the device, in the shape of Pipeline (pipeline.hpp; ownership,
// queues, events and threads as it says): prefilter() builds what the method reads (cssm: basis
// + mips or SAT; ssmm: min-depth pyramid), reconstruct() writes the visibility of the receivers.
class SoftFilter {
 public:
  SoftFilter(std::shared_ptr<Runtime> rt, SoftOptions opt, int width, int height);
  cl::Event prefilter(const cl::Buffer& depth, const EventList* wait = nullptr);
  // Visibility of the receivers' map part (u, v, d, f; DeviceReceivers, device_types.hpp: f
  // empty = footprint 1, row as there; grid receivers are not taken) into `visibility`
  // (rx.count floats), after prefilter()'s event in `wait`.
  cl::Event reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const EventList* wait = nullptr);
  // The same, cssm only, also writing z_avg per receiver into `zavg` (NaN where no blocker was
  // found).
  cl::Event reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const cl::Buffer& zavg,
                        const EventList* wait = nullptr);
  // Device seconds of the last prefilter/reconstruct (the stages of the method; waits for their events).
  StageTimes times() const;
  // Bytes of the buffers this filter allocated.
  size_t device_bytes() const { return device_bytes_; }
  const SoftOptions& options() const { return opt_; }

 private:
  std::shared_ptr<Runtime> rt_;
  SoftOptions opt_;
  int W_, H_;
  size_t device_bytes_ = 0;
  cl::Buffer depth_, basis_, chain_, sat_, bands_, packed_;  // packed_: cssm's interleaved SAT
  cl::Event transform_done_, run_done_, pack_done_;
  cl::Event pyr_first_, pyr_done_, sat_first_, sat_done_;
  bool have_pyr_ = false, have_sat_ = false, have_transform_ = false;
  // The fills that fault in the buffers on a CPU device (StageTimes::resident), reported with
  // the first frame.
  cl::Event resident_first_, resident_done_;
  int prefilters_ = 0;
};

// Host convenience: one light.
// The counts are the first light's receivers'; times and device bytes are summed over the lights.
struct SoftResult : VisibilityResult {};
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

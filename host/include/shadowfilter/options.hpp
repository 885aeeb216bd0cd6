#pragma once
// Every knob of a filtering run, with its default and why (in the spirit of Filament's
// shadow Options.h). Method-specific structs sit beside the generic ones.
#include <iosfwd>
#include <map>
#include <optional>
#include <string>

#include "shadowfilter/map_range.hpp"

namespace sf {

struct MethodDesc;  // methods.hpp

// A registered method: a handle to its registration (methods.hpp), esm by default. Options carry
// the handle, so the library never looks a method up by name once the options exist.
//
// A name converts implicitly and is resolved at once (an unknown name throws InputError naming
// the known methods, right where it is written): C++ callers and tests write o.method = "vsm" as
// they would write a literal, and the conversion is the boundary where the name is parsed. The
// CLI, files and bindings parse names explicitly with sf::method(name). The library itself only
// holds, compares and dereferences handles.
class Method {
 public:
  Method() = default;  // esm
  Method(const MethodDesc& desc) : desc_(&desc) {}
  Method(const std::string& name);
  Method(const char* name);
  const MethodDesc& desc() const;
  const MethodDesc& operator*() const { return desc(); }
  const MethodDesc* operator->() const { return &desc(); }
  const std::string& name() const;
  friend bool operator==(const Method& a, const Method& b) { return &a.desc() == &b.desc(); }
  friend bool operator!=(const Method& a, const Method& b) { return !(a == b); }

 private:
  const MethodDesc* desc_ = nullptr;  // nullptr: esm
};
std::ostream& operator<<(std::ostream& out, const Method& m);  // its name

struct EsmOptions {
  // Exponent c of exp(c z). Larger: sharper, less light leaking, but a wider failure band near
  // contact, which the default classification (EsmClassifyOptions) hands to its fall-back. 120 is
  // the measured default with z-max classification (docs/results.md "Defaults sweep"; the seed's
  // float32 value is 80); the centred storage holds c <= 174 in float32.
  float c = 120.0f;
};

// Storage format of the basis images (kernels/storage.clh). Filters compute in float whatever
// the storage; f16 halves and unorm8 quarters the memory and bandwidth of every pass.
enum class Storage { F32 = 0, F16 = 1, Unorm16 = 2, Unorm8 = 3 };
const char* storage_name(Storage s);        // "f32", "f16", "unorm16", "unorm8"
Storage parse_storage(const std::string&);  // throws InputError for other names
int storage_bytes(Storage s);               // bytes per stored value
// unorm16 and unorm8 hold [0,1] only: a method maps its bounded basis there (storage.clh's
// SF_STORAGE_UNORM on the device).
bool storage_unorm(Storage s);

// Depth bias b of the methods that test depths directly (sm, pcf: H(z - d_t + b); msm: the
// receiver depth becomes d - b). Unset = the method's default (depth_bias() in methods.hpp),
// measured (docs/results.md "Defaults sweep"): sm and pcf 0.003 against the receiver plane (0
// without it, where they equal s_ref of d), msm 0 and msm-hausdorff 3e-4 in float32; msm in
// unorm16 needs a small bias to keep flat receivers lit through the quantisation (docs/methods.md).
struct DepthTestOptions {
  std::optional<float> bias;
};

// Receiver-plane depth of the depth tests (sm, pcf; docs/receiver_plane.md): each texel t of a
// receiver's support is tested against the receiver's plane at t, d + (dd/dx, dd/dy) . (t - x),
// the gradient from the receiver's neighbours (receiver image or receiver-depth map), else from
// the depth map's slope, so tilted receivers do not shadow themselves and need no large bias.
struct ReceiverPlaneOptions {
  bool enabled = true;
  // Largest |dd/dx|, |dd/dy| in depth per level-0 texel (steeper is clamped): 0.1 is 88.9 degrees
  // on a 512-texel map of a scene as deep as it is wide; a steeper gradient is a wrong neighbour.
  float max_slope = 0.1f;
  // Slope-scaled bias in texels: the test's bias grows by slope_bias (|dd/dx| + |dd/dy|). The
  // plane is exact for planar receivers only; on curved and faceted ones, and where its gradient
  // comes from neighbours texels away, it errs by a fraction of a texel's depth change. 0 by
  // measurement (docs/results.md, "Defaults sweep"): on grazing receivers (terrain, the bunny)
  // a slope-scaled term lets occluders close above them leak, where the constant bias of the
  // method keeps the acne targets with fewer leaks.
  float slope_bias = 0.0f;
};

struct VsmOptions {
  // Minimum variance v_min; negative = the method's default for the storage (docs/methods.md;
  // measured, docs/results.md "Defaults sweep"). vsm: absolute floor of bar(z^2) - bar(z)^2,
  // default 1e-6 in float32 and 2e-5 in the 16-bit storages (a flat receiver stays lit when its
  // stored mean is rounded by half a float16 ulp). evsm: relative, the floor per side is
  // (v_min c |warped d|)^2, default 1e-3 in float32 and 2e-3 in float16.
  float min_variance = -1.0f;
  // Light-bleeding reduction a in [0, 1): v = clamp((p - a) / (1 - a), 0, 1). 0 = none.
  float lbr = 0.0f;
};

struct EvsmOptions {
  // Exponents of the positive and negative warps (Annen 2008 / Lauritzen). Clamped to what the
  // storage holds: exp(2 c w) must stay finite, c <= 42 in float32 and 5.54 in float16. Negative =
  // the method's measured default (docs/results.md "Defaults sweep"): evsm2 c+ = 5, evsm4 c+ = 10
  // and c- = 5; larger warps sharpen the bound's penumbrae past the ray-traced ones.
  float pos = -1.0f;
  float neg = -1.0f;
};

struct MsmOptions {
  // Moment bias a: b = (1 - a) bar(B) + a (1/2, ...). Negative = the storage's default,
  // in float32 1e-4 for msm and 1e-3 for msm-hausdorff (measured, docs/results.md "Defaults
  // sweep"; Peters & Klein suggest 3e-5) and 6e-5 in unorm16 (Peters & Klein 2015 with the
  // optimised quantisation).
  float moment_bias = -1.0f;
};

struct CsmOptions {
  int order = 8;       // M: 2M basis planes (sin, cos of (2k - 1) pi z), 1..32
  float alpha = 0.0f;  // ringing attenuation g_k = exp(-alpha (k/M)^2); 0 = none
  // Offset and scale of the reconstruction (v = clamp(scale f(d - offset), 0, 1)). Negative =
  // the measured default for the order (docs/methods.md: lit receivers reconstruct to
  // >= 1 - 1/255 with the least error against s_ref on the bundled scene).
  float offset = -1.0f;
  float scale = -1.0f;
};

struct BlurOptions {
  // Gaussian taps -R..R applied to the basis images before the lookup; 0 = no prefilter.
  int radius = 0;
  // Standard deviation in texels; 0 = (2R+1)/6, so that the taps span +-3 sigma.
  float sigma = 0.0f;
};

// How receivers read the filtered basis (methods.md sec. 2; docs/lookups.md). The receivers'
// footprint f (level-0 texels, 1 when missing) drives mips and sat; bilinear ignores it.
enum class Lookup { Bilinear = 0, Mips = 1, Sat = 2 };
struct LookupOptions {
  // bilinear: no pyramid (fastest, aliases under minification); mips: trilinear at
  // LOD log2(f) over the mean pyramid; sat: area-weighted box of side f via a summed-area table.
  Lookup kind = Lookup::Bilinear;
  // Receivers that carry a Jacobian (Receivers::dudx ...): mips and sat read up to this many
  // probes along the footprint's major axis (footprint.hpp; docs/lookups.md "Anisotropic
  // footprints"), pcf its filtered test over the same probes. 1 = the isotropic lookup at f.
  // In [1, kMaxAnisotropy].
  int max_anisotropy = 8;
  // Whether the lookup follows receivers' Jacobians (a footprint lookup of more than one probe).
  bool follows_jacobian() const { return kind != Lookup::Bilinear && max_anisotropy > 1; }
};

// ESM failure classification (Annen 2008 ch. 7.3): flagged receivers fall back to a 2x2 PCF of
// the ESM test on the raw depth. Auto (the default) is zmax for a method that can be classified
// (esm) and none for every other: ESM alone leaks wherever a receiver's support also holds texels
// behind it (up to 38% of terrain's umbra), and no exponent removes that (docs/results.md
// "Defaults sweep", with what the stage costs per frame). classify_mode() (methods.hpp) resolves it.
enum class EsmClassify { None = 0, ZMax = 1, Threshold = 2, Auto = 3 };
struct EsmClassifyOptions {
  EsmClassify mode = EsmClassify::Auto;
  // zmax: flag when some texel of the lookup's support has z > d + offset. The offset keeps
  // lit receivers whose own surface slopes away within the support from being flagged; 0.02
  // is the measured balance between flagging ESM's failures and flagging lit receivers
  // (docs/lookups.md, "The default z-max offset").
  float zmax_offset = 0.02f;
  // threshold: flag when exp(-c d) bar(B) > 1 + eps. Negative = automatic,
  // exp(c offset)(1 + 1e-5) - 1: then threshold flags a subset of zmax.
  float threshold_eps = -1.0f;
};

// Which family of launch shapes the blur, the SAT and the pyramid use (docs/gpu.md, "Launch
// shapes"). Cpu: one work-item per long strip or band (work-groups of one item, SIMD inside it:
// tuned for PoCL). Gpu: work-groups of 64-256 items, one item per output texel, local-memory
// tiles. Auto: the defaults table by device type (CPU devices take Cpu, GPUs and accelerators
// take Gpu; host/src/runtime/schedule_defaults.cpp). Forcing Gpu on a CPU device is how the GPU shapes
// are tested on PoCL and Oclgrind.
enum class ScheduleFamily { Auto = 0, Cpu = 1, Gpu = 2 };
const char* schedule_family_name(ScheduleFamily f);        // "auto", "cpu", "gpu"
ScheduleFamily parse_schedule_family(const std::string&);  // throws InputError for other names

// How the kernels are scheduled (Halide-style: what is computed does not depend on these).
struct ScheduleOptions {
  // Launch-shape family of the blur, SAT and pyramid; Auto = by device type (see above).
  ScheduleFamily family = ScheduleFamily::Auto;
  // Work-items per work-group of the Gpu family's kernels (a power of two, 1..1024); 0 = the
  // defaults table (256). The kernels fall back to smaller groups where the device or the
  // kernel allows fewer items or less local memory.
  int gpu_work_group = 0;
  // Texels per vector in the blur (4, 8 or 16): wide vector loads on CPUs.
  int blur_vector_width = 16;
  // Blur work-item tile: texels along a row (a multiple of the vector width) and output rows.
  // 0 = chosen from the radius and the image size (kernels.cpp, enqueue_blur).
  int blur_strip_texels = 0;
  int blur_rows = 0;
  // Work-group size for 1-D kernels; 0 lets the driver choose.
  int work_group_size = 0;
  // Texels per explicit vector in the basis transform (4, 8 or 16); 1 = one texel per
  // work-item, left to PoCL's vectoriser (the scalar baseline of the benchmarks).
  int transform_vector_width = 16;
  // Receivers per work-item of the points reconstruction (4, 8 or 16): the lookup's coordinate
  // math and the visibility run as vectors of this width; 1 = one receiver per work-item.
  int reconstruct_vector_width = 16;
};

struct FilterOptions {
  Method method;  // esm; see `shadowfilter methods`
  EsmOptions esm;
  DepthTestOptions depth_test;
  ReceiverPlaneOptions receiver_plane;
  VsmOptions vsm;
  EvsmOptions evsm;
  MsmOptions msm;
  CsmOptions csm;
  Storage storage = Storage::F32;  // basis images, see `shadowfilter methods` for what fits
  BlurOptions blur;
  LookupOptions lookup;
  EsmClassifyOptions esm_classify;
  ScheduleOptions schedule;
  // sf::filter: receivers whose ndl (the receiver image's fifth channel) is <= 0 face away from
  // the light and get visibility 0, as the ray-traced references have them (sf::shadow_facing_away).
  bool facing_away_shadowed = true;
  // sf::filter: texels each lookup moves along the receiver's normal before any method reads
  // the map, where the receivers carry one (Receivers::nx ny nz; normal_offset.hpp), in
  // [0, kMaxNormalOffset]; 0 = off; < 0 = the method's measured default
  // (MethodDesc::default_normal_offset, sf::normal_offset; docs/results.md "Normal offset").
  float normal_offset = -1.0f;
  // The depth range of the maps this pipeline filters, where a lookup's limit depends on it (esm
  // and evsm with sat: MethodDesc::sat_limit). Set, the Pipeline checks it when it is built
  // (a range narrower than a map's voids the error bound for that map); unset, prefilter()
  // measures each map on the device first (a blocking reduction, depth_range.hpp). sf::filter
  // sets it from the host map.
  std::optional<MapRange> depth_range;
  // The parameters of methods registered without a field of their own (sf::register_method with
  // Parameter::stored, parameters.hpp), keyed by the parameter's key; absent = its default. A key
  // that no registered method declares is refused.
  std::map<std::string, double> parameters;
};

// Throws InputError naming the first floating-point field of `o` that is not finite (every
// field, whether the method reads it or not: a NaN is never a default), or a key of
// FilterOptions::parameters that no registered method declares. The fields checked are the
// declared ones (parameters.hpp: the FilterOptions-wide knobs and every method's parameters).
void require_finite_options(const FilterOptions& o);

}  // namespace sf

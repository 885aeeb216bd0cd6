// Soft-shadow methods on the device (kernels/soft/*.cl; docs/soft.md).
#include <algorithm>
#include <cmath>

#include "cl_errors.hpp"
#include "launch.hpp"
#include "plane_params.hpp"
#include "resident.hpp"
#include "shared_types.clh"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/footprint.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/normal_offset.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/soft.hpp"

namespace sf {
namespace {

// The kernels' parameter structs (shared_types.clh).
using ClSoftLight = sf_soft_light;
using ClCssmParams = sf_cssm_params;

constexpr double kPi = 3.14159265358979323846;

ClSoftLight cl_light(const SoftOptions& o) {
  const SoftLight& L = o.light;
  ClSoftLight c{};
  const double unit = soft_side_scale(L);
  c.ku = float(L.size * unit);
  c.kv = float(light_height(L) * unit);
  const SoftDistance D = soft_distance(L);
  c.a = float(D.a);
  c.b = float(D.b);
  c.persp = L.perspective ? 1 : 0;
  c.bias = o.bias;
  c.max_width = o.max_width;
  return c;
}

const std::vector<std::string> kSoftHeaders = {"common.clh", "storage.clh", "lookup.clh", "receiver_plane.clh",
                                               "soft/soft_common.clh"};

// jacobian: the receivers' footprints are Jacobians (-DSF_SOFT_JACOBIAN, soft_common.clh).
cl::Program cssm_program(Runtime& rt, const SoftOptions& o, bool jacobian = false) {
  const int M = o.cssm.order;
  std::vector<std::string> files = kSoftHeaders;
  files.push_back("soft/cssm.cl");
  return rt.program(files, detail::BuildOptions()
                               .define("SF_CSSM_ORDER", M)
                               .define("SF_CHANNELS", 4 * M + 1)
                               .lookup(o.cssm.lookup)
                               .storage(o.cssm.storage)
                               .flag_if(jacobian, "SF_SOFT_JACOBIAN")
                               .str());
}

}  // namespace

const char* soft_method_name(SoftMethod m) {
  switch (m) {
    case SoftMethod::Pcss:
      return "pcss";
    case SoftMethod::Cssm:
      return "cssm";
    case SoftMethod::Ssmm:
      return "ssmm";
    case SoftMethod::SsmmImproved:
      return "ssmm-improved";
  }
  return "?";
}

SoftMethod find_soft_method(const std::string& name) {
  std::string known;
  for (SoftMethod m : {SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}) {
    if (name == soft_method_name(m)) return m;
    known += (known.empty() ? "" : ", ") + std::string(soft_method_name(m));
  }
  throw InputError("unknown soft method '" + name + "' (known: " + known + ")");
}

double light_height(const SoftLight& L) { return L.height >= 0.0 ? L.height : L.size; }

double soft_side_scale(const SoftLight& L) {
  return L.perspective ? 1.0 / (2.0 * std::tan(0.5 * L.fov_degrees * kPi / 180.0)) : 1.0 / L.extent;
}

namespace {
// The footprint of a light side of length `side` (soft_width, soft_height).
double footprint(const SoftLight& L, double side, double d, double z) {
  const double k = side * soft_side_scale(L);
  const SoftDistance D = soft_distance(L);
  const double DR = std::max(D.a + D.b * d, 1e-20), DB = std::max(D.a + D.b * z, 1e-20);
  const double w = k * std::max(DR - DB, 0.0) / DR;
  return L.perspective ? w / DB : w;
}

// The light's sides (soft_light, validate): size >= 0, height finite (< 0: a square).
void check_sides(double size, double height) {
  if (!(size >= 0.0) || !std::isfinite(size)) throw InputError("SoftOptions::light.size must be a finite number >= 0");
  if (!std::isfinite(height))
    throw InputError("SoftOptions::light.height must be a finite number (< 0: size, a square light)");
}
}  // namespace

float soft_normal_offset(const SoftOptions& o) {
  if (o.normal_offset >= 0.0f) return o.normal_offset;
  return o.method == SoftMethod::Cssm ? 0.0f : 0.5f;  // cssm: no depth test to lift (leak 8.0% -> 5.9%, worst RMSE +5%)
}

SoftDistance soft_distance(const SoftLight& L) {
  if (L.perspective) return {L.near_plane, L.far_plane - L.near_plane};
  return {L.light_distance / (L.far_plane - L.near_plane), 1.0};
}

double soft_width(const SoftLight& L, double d, double z) { return footprint(L, L.size, d, z); }
double soft_height(const SoftLight& L, double d, double z) { return footprint(L, light_height(L), d, z); }

SoftLight soft_light(const ViewProjection& view, double size, double height) {
  check_sides(size, height);
  const ProjectionDepth pd = light_projection_depth(view);
  const double x_scale = std::fabs(view.projection[0]);
  SoftLight L;
  L.perspective = pd.perspective;
  L.size = size;
  L.height = height;
  L.near_plane = pd.near_plane;
  L.far_plane = pd.far_plane;
  if (pd.perspective)
    L.fov_degrees = 2.0 * std::atan(1.0 / x_scale) * 180.0 / kPi;
  else
    L.extent = 2.0 / x_scale;
  return L;
}

const std::vector<std::pair<std::string, std::string>>& soft_option_flags() {
  static const std::vector<std::pair<std::string, std::string>> table = {
      {"SoftOptions::receiver_plane.slope_bias", "--slope-bias"},
      {"SoftOptions::receiver_plane.max_slope", "--receiver-plane-max-slope"},
      {"SoftOptions::light.size", "--light-size"},
      {"SoftOptions::light.height", "--light-size"},
      {"SoftOptions::light.near_plane", "--light-near"},
      {"SoftOptions::light.fov_degrees", "--light-fov"},
      {"SoftOptions::light.extent", "--light-extent"},
      {"SoftOptions::bias", "--soft-bias"},
      {"SoftOptions::normal_offset", "--normal-offset"},
      {"SoftOptions::max_width", "--soft-max-width"},
      {"SoftOptions::cssm.order", "--cssm-order"},
      {"SoftOptions::cssm.lookup", "--lookup"},
      {"SoftOptions::cssm.offset", "--cssm-offset"},
      {"SoftOptions::cssm.scale", "--cssm-scale"},
      {"SoftOptions::cssm.sharpen_a", "--cssm-sharpen A"},
      {"SoftOptions::cssm.sharpen_b", "--cssm-sharpen B"},
      {"SoftOptions::cssm.min_den", "--cssm-min-den"},
      {"SoftOptions::cssm.z_offset", "--cssm-z-offset"},
      {"SoftOptions::cssm.width_scale", "--cssm-width-scale"},
      {"SoftOptions::cssm.storage", "--cssm-storage"},
      {"SoftOptions::ssmm.n", "--ssmm-n"},
  };
  return table;
}

double cssm_series(int M, double x) {
  double s = 0;
  for (int k = 0; k < M; ++k) {
    const double ck = (2 * k + 1) * kPi;
    s += std::sin(ck * x) / ck;
  }
  return 0.5 + 2 * s;
}

CssmParams cssm_params(const SoftOptions& o) {
  const float M = float(std::max(o.cssm.order, 1));
  CssmParams p;
  p.offset = o.cssm.offset >= 0.0f ? o.cssm.offset : 0.2f / M;
  p.z_offset = cssm_z_offset(o);
  p.scale = o.cssm.scale > 0.0f ? o.cssm.scale : 1.5f;
  p.lit = float(cssm_series(o.cssm.order, p.offset));
  // A straight edge's filtered lit fraction q gives v = 0.5 + scale (q lit - 0.5) (q / 1 when
  // normalised): the ramp is steeper by scale lit, so the kernel widens by that to keep the width.
  const float gain = o.cssm.normalise ? p.scale : p.scale * p.lit;
  p.width_scale = o.cssm.width_scale > 0.0f ? o.cssm.width_scale : std::max(gain, 1.0f);
  p.sharpen_a = o.cssm.sharpen_a;
  p.sharpen_b = o.cssm.sharpen_b >= 0.0f ? o.cssm.sharpen_b : 10.0f * M;
  return p;
}

float cssm_z_offset(const SoftOptions& o) {
  if (o.cssm.z_offset >= 0.0f) return o.cssm.z_offset;
  // Default: the smallest x > 0 where the series reaches 1 (~0.306 / M): a lit texel (z = d) then
  // has blocker weight 1 - f = 0 and does not pull z_avg (at 0.5 / M its negative weight pushed
  // z_avg away from d and widened the penumbra: docs/soft.md).
  const int M = std::max(o.cssm.order, 1);
  double lo = 0.0, hi = 0.5 / M;  // f(0) = 0.5, f(0.5 / M) ~ 1.09
  for (int i = 0; i < 50; ++i) (cssm_series(M, 0.5 * (lo + hi)) < 1.0 ? lo : hi) = 0.5 * (lo + hi);
  return float(hi);
}

void validate(const SoftOptions& o) {
  const SoftLight& L = o.light;
  check_sides(L.size, L.height);
  if (!(L.far_plane > L.near_plane)) throw InputError("the light's far plane must lie beyond its near plane");
  if (L.perspective) {
    if (!(L.near_plane > 0.0)) throw InputError("a perspective light needs SoftOptions::light.near_plane > 0");
    if (!(L.fov_degrees > 0.0 && L.fov_degrees < 180.0))
      throw InputError("a perspective light needs SoftOptions::light.fov_degrees between 0 and 180 degrees");
  } else if (!(L.extent > 0.0) || !std::isfinite(L.extent)) {
    throw InputError("an orthographic light needs SoftOptions::light.extent > 0 (the map's width in light units)");
  } else if (!std::isfinite(L.light_distance) ||
             (L.light_distance != 0.0 && !std::isfinite(L.light_distance / (L.far_plane - L.near_plane)))) {
    throw InputError(
        "SoftOptions::light.light_distance must be a finite number, and with it near and far finite planes");
  }
  if (!(L.weight >= 0.0) || !std::isfinite(L.weight)) throw InputError("light weights must be >= 0");
  if (!(o.bias >= 0.0f && o.bias < 1.0f)) throw InputError("SoftOptions::bias must be in [0, 1)");
  if (!(o.normal_offset <= kMaxNormalOffset))  // NaN fails too; < 0: the method's
    throw InputError("SoftOptions::normal_offset must be in [0, " + std::to_string(int(kMaxNormalOffset)) +
                     "] texels (< 0: the method's)");
  if (!(o.max_width >= 1.0f && o.max_width <= 4096.0f)) throw InputError("SoftOptions::max_width must be in [1, 4096]");
  if (o.cssm.order < 1 || o.cssm.order > 32) throw InputError("SoftOptions::cssm.order must be 1..32");
  if (o.cssm.lookup != Lookup::Mips && o.cssm.lookup != Lookup::Sat)
    throw InputError("cssm needs SoftOptions::cssm.lookup mips or sat");
  if (!std::isfinite(o.cssm.offset) || o.cssm.offset >= 1.0f) throw InputError("SoftOptions::cssm.offset must be < 1");
  if (!std::isfinite(o.cssm.scale) || o.cssm.scale == 0.0f || o.cssm.scale > 64.0f)
    throw InputError("SoftOptions::cssm.scale must be in (0, 64] (< 0: default)");
  if (!(o.cssm.sharpen_a >= 0.0f) || !std::isfinite(o.cssm.sharpen_a) || !std::isfinite(o.cssm.sharpen_b))
    throw InputError(
        "SoftOptions::cssm.sharpen_a must be >= 0 (0: off) and SoftOptions::cssm.sharpen_b finite (< 0: default 10 M)");
  if (!(o.cssm.min_den > 0.0f && o.cssm.min_den < 1.0f))
    throw InputError("SoftOptions::cssm.min_den must be in (0, 1)");
  if (!std::isfinite(o.cssm.z_offset) || o.cssm.z_offset >= 1.0f)
    throw InputError("SoftOptions::cssm.z_offset must be < 1");
  if (!std::isfinite(o.cssm.width_scale) || o.cssm.width_scale == 0.0f || o.cssm.width_scale > 64.0f)
    throw InputError("SoftOptions::cssm.width_scale must be in (0, 64] (< 0: the scale)");
  if (!(cssm_series(o.cssm.order, cssm_params(o).offset) > 0.05))
    throw InputError("SoftOptions::cssm.offset too small to normalise by (the series of a lit texel must exceed 0.05)");
  if (const CssmParams c = cssm_params(o); c.sharpen_a > 0.0f) {
    // Sharpening raises v to the power 1 + A at contact: a lit receiver must reconstruct to 1.
    const double lit = 0.5 + c.scale * ((o.cssm.normalise ? 1.0 : c.lit) - 0.5);
    if (lit < 0.999)
      throw InputError("cssm: a lit receiver reconstructs to " + std::to_string(lit).substr(0, 5) +
                       " < 1 with this SoftOptions::cssm.offset / SoftOptions::cssm.scale, which "
                       "SoftOptions::cssm.sharpen_a would darken; "
                       "raise the offset or the scale, or give SoftOptions::cssm.sharpen_a = 0");
  }
  if (o.cssm.storage != Storage::F32 && o.cssm.lookup != Lookup::Mips)
    throw InputError(std::string("SoftOptions::cssm.storage ") + storage_name(o.cssm.storage) +
                     " needs SoftOptions::cssm.lookup mips: the SAT's table is float-float whatever its input");
  if (o.cssm.storage == Storage::Unorm8)
    throw InputError(
        "SoftOptions::cssm.storage unorm8 is refused: on the soft scenes it moves cssm's visibility 0.03-0.05 RMS "
        "from float32's, f16 and unorm16 0.0003-0.0025 (docs/soft.md); give f32, f16 or unorm16");
  if (o.ssmm.n < 1 || o.ssmm.n > 64) throw InputError("SoftOptions::ssmm.n must be 1..64");
  detail::validate(o.receiver_plane, "SoftOptions::receiver_plane");
}

SoftFilter::SoftFilter(std::shared_ptr<Runtime> rt, SoftOptions opt, int width, int height) try
    : rt_(std::move(rt)), opt_(std::move(opt)), W_(width), H_(height) {
  validate(opt_);
  if (W_ <= 0 || H_ <= 0) throw InputError("empty shadow map");
  auto alloc = [this](size_t bytes) {
    bytes = std::max<size_t>(bytes, 4);
    check_fits_device(*rt_, bytes, device_bytes_ + bytes, "the soft-shadow buffers");
    device_bytes_ += bytes;
    return cl::Buffer(rt_->context(), CL_MEM_READ_WRITE, bytes);
  };
  if (opt_.method == SoftMethod::Cssm) {
    ImageShape s{W_, H_, 4 * opt_.cssm.order + 1, storage_bytes(opt_.cssm.storage)};
    basis_ = alloc(s.bytes());
    if (opt_.cssm.lookup == Lookup::Mips) {
      chain_ = alloc(mip_layout(W_, H_, s.channels).chain_values * s.value_bytes);
    } else {
      const SatLayout L = sat_layout(s);
      sat_ = alloc(L.table_floats * sizeof(float));
      bands_ = alloc(L.band_floats * sizeof(float));
      packed_ = alloc(size_t(2) * s.channels * (W_ + 1) * (H_ + 1) * sizeof(float));
    }
  } else if (opt_.method == SoftMethod::Ssmm || opt_.method == SoftMethod::SsmmImproved) {
    chain_ = alloc(mip_layout(W_, H_, 1).chain_values * sizeof(float));
  }
  // Every buffer's pages in before the first frame (resident.hpp).
  resident_done_ = detail::fault_in(*rt_, {&basis_, &chain_, &sat_, &bands_, &packed_}, &resident_first_);
} catch (const cl::Error& e) {
  detail::throw_device_error("SoftFilter::SoftFilter", e);
}

cl::Event SoftFilter::prefilter(const cl::Buffer& depth, const EventList* wait) try {
  depth_ = depth;
  have_pyr_ = have_sat_ = have_transform_ = false;
  if (prefilters_++ > 0) resident_first_ = resident_done_ = cl::Event();  // reported with the first frame
  if (opt_.method == SoftMethod::Cssm) {
    const int M = opt_.cssm.order;
    cl::Kernel k(cssm_program(*rt_, opt_), "sf_cssm_basis");
    const int texels = W_ * H_;
    detail::KernelArgs(k).buffer(depth).buffer(basis_).value(texels);
    rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(size_t(texels)), cl::NullRange, wait,
                                      &transform_done_);
    have_transform_ = true;
    EventList after{transform_done_};
    ImageShape s{W_, H_, 4 * M + 1, storage_bytes(opt_.cssm.storage)};
    if (opt_.cssm.lookup == Lookup::Mips) {
      pyr_done_ = enqueue_pyramid(*rt_, Reduce::Mean, opt_.cssm.storage, {}, s, basis_, chain_, &pyr_first_, &after);
      have_pyr_ = true;
      return pyr_done_;
    }
    sat_done_ = enqueue_sat(*rt_, Storage::F32, {}, {}, s, basis_, sat_, bands_, &sat_first_, &after);
    have_sat_ = true;
    cl::Kernel pk(cssm_program(*rt_, opt_), "sf_cssm_sat_pack");
    const int entries = (W_ + 1) * (H_ + 1);
    detail::KernelArgs(pk).buffer(sat_).buffer(packed_).value(W_).value(H_);
    EventList after_sat{sat_done_};
    rt_->queue().enqueueNDRangeKernel(pk, cl::NullRange, cl::NDRange(size_t(entries)), cl::NullRange, &after_sat,
                                      &pack_done_);
    return pack_done_;
  }
  if (opt_.method == SoftMethod::Ssmm || opt_.method == SoftMethod::SsmmImproved) {
    pyr_done_ = enqueue_pyramid(*rt_, Reduce::Min, Storage::F32, {}, ImageShape{W_, H_, 1, 4}, depth, chain_,
                                &pyr_first_, wait);
    have_pyr_ = true;
    return pyr_done_;
  }
  cl::Event e;
  rt_->queue().enqueueMarkerWithWaitList(wait, &e);
  return e;
} catch (const cl::Error& e) {
  detail::throw_device_error("SoftFilter::prefilter", e);
}

cl::Event SoftFilter::reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const EventList* wait) {
  return reconstruct(rx, visibility, cl::Buffer(), wait);
}

cl::Event SoftFilter::reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const cl::Buffer& zavg,
                                  const EventList* wait) try {
  if (rx.grid) throw InputError("SoftFilter::reconstruct takes points (DeviceReceivers::grid must be false)");
  if (rx.count > 0 && (!rx.u() || !rx.v() || !rx.d()))
    throw InputError("SoftFilter::reconstruct: DeviceReceivers::u, v and d must be buffers");
  // The receivers' footprints: their Jacobians where given (the rectangle bounding each pixel's
  // parallelogram, soft_common.clh), else f.
  const bool jacobian = rx.jacobian() != nullptr;
  const cl::Buffer &u = rx.u, &v = rx.v, &d = rx.d, &f = jacobian ? rx.jacobian : rx.f;
  const size_t count = rx.count;
  const int receiver_row = rx.row;
  const ClSoftLight L = cl_light(opt_);
  // Every points kernel takes (its maps, W, H in its order), then (u, v, d, f, visibility
  // [, zavg], count, light [, its parameters]).
  cl::Kernel k;
  if (opt_.method == SoftMethod::Pcss) {
    std::vector<std::string> files = kSoftHeaders;
    files.push_back("soft/pcss.cl");
    k = cl::Kernel(
        rt_->program(files,
                     detail::BuildOptions().define("SF_CHANNELS", 1).flag_if(jacobian, "SF_SOFT_JACOBIAN").str()),
        "sf_pcss_points");
  } else if (opt_.method == SoftMethod::Cssm) {
    k = cl::Kernel(cssm_program(*rt_, opt_, jacobian), "sf_cssm_points");
  } else {
    std::vector<std::string> files = kSoftHeaders;
    files.push_back("soft/ssmm.cl");
    k = cl::Kernel(
        rt_->program(files,
                     detail::BuildOptions().define("SF_CHANNELS", 1).flag_if(jacobian, "SF_SOFT_JACOBIAN").str()),
        "sf_ssmm_points");
  }
  detail::KernelArgs args(k);
  if (opt_.method == SoftMethod::Pcss)
    args.optional(depth_).value(W_).value(H_);
  else if (opt_.method == SoftMethod::Cssm)
    args.optional(basis_).value(W_).value(H_).optional(chain_).optional(packed_);
  else
    args.optional(depth_).optional(chain_).value(W_).value(H_);
  args.optional(u).optional(v).optional(d).optional(f).optional(visibility);
  if (opt_.method == SoftMethod::Cssm) args.optional(zavg);
  args.value(static_cast<int>(count)).value(L);
  if (opt_.method == SoftMethod::Cssm) {
    const CssmParams c = cssm_params(opt_);
    const ClCssmParams P{c.offset,
                         c.scale,
                         c.sharpen_a,
                         c.sharpen_b,
                         opt_.cssm.min_den,
                         c.z_offset,
                         c.width_scale,
                         opt_.cssm.normalise ? 1.0f / c.lit : 1.0f,
                         opt_.cssm.contact ? 1 : 0};
    args.value(P);
  } else if (opt_.method != SoftMethod::Pcss) {
    args.value(opt_.ssmm.n).value(opt_.method == SoftMethod::SsmmImproved ? 1 : 0);
  }
  if (opt_.method != SoftMethod::Cssm) args.value(detail::plane_params(opt_.receiver_plane, receiver_row));
  rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(std::max<size_t>(count, 1)), cl::NullRange, wait,
                                    &run_done_);
  return run_done_;
} catch (const cl::Error& e) {
  detail::throw_device_error("SoftFilter::reconstruct", e);
}

StageTimes SoftFilter::times() const try {
  StageTimes t;
  if (have_transform_) t.transform = event_seconds(transform_done_);
  if (have_pyr_) t.pyramid = event_seconds(pyr_first_, pyr_done_);
  if (have_sat_) t.sat = event_seconds(sat_first_, pack_done_() ? pack_done_ : sat_done_);
  if (run_done_()) t.reconstruct = event_seconds(run_done_);
  t.resident = detail::resident_seconds(resident_first_, resident_done_);
  return t;
} catch (const cl::Error& e) {
  detail::throw_device_error("SoftFilter::times", e);
}

namespace {

struct HostPoints {
  std::vector<float> u, v, d, f;
  bool has_f = false;
  std::vector<float> jacobian;  // dudx, dvdx, dudy, dvdy one after the other; empty without
};

HostPoints points_of(const Receivers& rx, int W, int H) {
  HostPoints p;
  p.d = rx.d;
  if (rx.grid) {
    p.u.resize(rx.count());
    p.v.resize(rx.count());
    for (int y = 0; y < rx.height; ++y)
      for (int x = 0; x < rx.width; ++x) {
        p.u[size_t(y) * rx.width + x] = (x + 0.5f) / float(W);
        p.v[size_t(y) * rx.width + x] = (y + 0.5f) / float(H);
      }
  } else {
    p.u = rx.u;
    p.v = rx.v;
    if (rx.has_footprint) {
      p.f = rx.f;
      p.has_f = true;
    }
    if (rx.has_jacobian) jacobian_planes(rx, p.jacobian);
  }
  return p;
}

cl::Buffer upload(Runtime& rt, const std::vector<float>& h) {
  cl::Buffer b(rt.context(), CL_MEM_READ_WRITE, std::max<size_t>(h.size(), 1) * sizeof(float));
  if (!h.empty()) rt.queue().enqueueWriteBuffer(b, CL_TRUE, 0, h.size() * sizeof(float), h.data());
  return b;
}

}  // namespace

SoftResult soft_filter_lights(std::shared_ptr<Runtime> rt, const SoftOptions& opt,
                              const std::vector<SoftLightInput>& lights) try {
  if (lights.empty()) throw InputError("no lights");
  SoftResult r;
  const Receivers& rx0 = lights.front().receivers;
  r.visibility = HostImage(rx0.width, rx0.height, 1, 0.0f);
  std::vector<double> acc(rx0.count(), 0.0);
  double wsum = 0.0;
  for (const auto& in : lights) {
    if (in.receivers.width != rx0.width || in.receivers.height != rx0.height)
      throw InputError("every light's receivers must have the same size");
    SoftOptions o = opt;
    o.light = in.light;
    SoftFilter sfl(rt, o, in.depth.width, in.depth.height);
    cl::Buffer depth = upload(*rt, in.depth.data);
    // Every lookup moved along its receiver's normal first (normal_offset.hpp).
    const float offset = soft_normal_offset(opt);
    const HostPoints p = in.receivers.has_normal && offset != 0.0f
                             ? points_of(offset_along_normals(in.receivers, in.depth.width, in.depth.height, offset),
                                         in.depth.width, in.depth.height)
                             : points_of(in.receivers, in.depth.width, in.depth.height);
    DeviceReceivers rx;
    rx.count = in.receivers.count();
    rx.row = in.receivers.width;
    rx.u = upload(*rt, p.u);
    rx.v = upload(*rt, p.v);
    rx.d = upload(*rt, p.d);
    if (p.has_f) rx.f = upload(*rt, p.f);
    if (!p.jacobian.empty()) rx.jacobian = upload(*rt, p.jacobian);
    const size_t n = rx.count;
    cl::Buffer out(rt->context(), CL_MEM_READ_WRITE, std::max<size_t>(n, 1) * sizeof(float));
    cl::Event prep = sfl.prefilter(depth);
    EventList after{prep};
    // out-of-order queues: wait on it
    const EventList ran{sfl.reconstruct(rx, out, &after)};
    std::vector<float> vis(n);
    if (n) rt->queue().enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(float), vis.data(), &ran);
    r.times += sfl.times();
    r.device_bytes +=
        sfl.device_bytes() + (in.depth.data.size() + (p.has_f ? 5 : 4) * n + p.jacobian.size()) * sizeof(float);
    size_t facing_away = 0;
    if (opt.facing_away_shadowed) facing_away = shadow_facing_away(in.receivers, vis);  // each light's own ndl
    if (&in == &lights.front()) r.facing_away = facing_away;
    for (size_t i = 0; i < n; ++i) acc[i] += in.light.weight * vis[i];
    wsum += in.light.weight;
    if (&in == &lights.front())
      for (size_t i = 0; i < n; ++i) {
        const float di = p.d[i];
        if (!std::isfinite(di))
          ++r.background;
        else if (!in.receivers.grid && (!(p.u[i] >= 0 && p.u[i] <= 1) || !(p.v[i] >= 0 && p.v[i] <= 1)))
          ++r.outside;
      }
  }
  if (!(wsum > 0.0)) throw InputError("the light weights sum to 0");
  for (size_t i = 0; i < acc.size(); ++i) r.visibility.data[i] = float(acc[i] / wsum);
  return r;
} catch (const cl::Error& e) {
  detail::throw_device_error("soft_filter_lights", e);
}

SoftResult soft_filter(std::shared_ptr<Runtime> rt, const SoftOptions& opt, const HostImage& depth,
                       const Receivers& receivers) try {
  return soft_filter_lights(rt, opt, {SoftLightInput{opt.light, depth, receivers}});
} catch (const cl::Error& e) {
  detail::throw_device_error("soft_filter", e);
}

}  // namespace sf

// The method registry: one entry per basis (kernels/methods/*.clh) plus the raw-depth tests
// sm and pcf (kernels/pcf.cl). Adding a method = its header, one function here, its reference
// (host/reference/methods_*.cpp) and its tests.
#include "shadowfilter/methods.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "shadowfilter/errors.hpp"

namespace sf {

const char* storage_name(Storage s) {
  switch (s) {
    case Storage::F32: return "f32";
    case Storage::F16: return "f16";
    case Storage::Unorm16: return "unorm16";
    case Storage::Unorm8: return "unorm8";
  }
  return "?";
}

Storage parse_storage(const std::string& name) {
  for (Storage s : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8})
    if (name == storage_name(s)) return s;
  throw InputError("unknown storage '" + name + "' (known: f32, f16, unorm16, unorm8)");
}

int storage_bytes(Storage s) {
  switch (s) {
    case Storage::F32: return 4;
    case Storage::F16:
    case Storage::Unorm16: return 2;
    case Storage::Unorm8: return 1;
  }
  return 4;
}

namespace {

// Largest ESM exponent whose centred storage exp(c (z - 1/2)) stays within normal float32
// numbers: exp(+-c/2) within [FLT_MIN, FLT_MAX] means c/2 <= 87.3.
constexpr float kEsmMaxCFloat32 = 174.0f;
// float16: exp(c/2) <= 65504 (the largest half) means c <= 2 ln 65504 = 22.18.
constexpr float kEsmMaxCFloat16 = 22.0f;
// EVSM stores exp(2 c w), w in [-1,1]: finite when 2c <= ln(max). float32: ln(3.4e38) = 88.7,
// c <= 44.3, and 42 leaves room for the Chebyshev sums; float16: ln(65504) / 2 = 5.54.
constexpr float kEvsmMaxFloat32 = 42.0f;
constexpr float kEvsmMaxFloat16 = 5.54f;
constexpr int kCsmMaxOrder = 32;

template <typename T>
std::vector<uint8_t> bytes_of(const T& v) {
  std::vector<uint8_t> b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

std::string num(float v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void require_finite(float v, const char* flag) {
  if (!std::isfinite(v)) throw InputError(std::string(flag) + " must be a finite number");
}

// The storage must be one the method lists (MethodDesc::storages).
void check_storage(const std::string& method, const std::string& allowed, const FilterOptions& o,
                   const std::string& why) {
  std::istringstream in(allowed);
  for (std::string s; in >> s;)
    if (s == storage_name(o.storage)) return;
  throw InputError(std::string("FilterOptions::storage ") + storage_name(o.storage) + " does not work with " +
                   method + " (it accepts " + allowed + "): " + why);
}

float evsm_limit(Storage s) { return s == Storage::F16 ? kEvsmMaxFloat16 : kEvsmMaxFloat32; }

MethodDesc raw_depth_method(const std::string& name, const std::string& summary) {
  MethodDesc m;
  m.name = name;
  m.summary = summary;
  m.raw_depth = true;
  m.channel_count = [](const FilterOptions&) { return 1; };
  m.parameters = "--bias B (default 0)";
  m.storages = "f32";
  m.validate = [name, st = m.storages](const FilterOptions& o) {
    require_finite(depth_bias(o), "FilterOptions::depth_test.bias");
    check_storage(name, st, o, "it tests the float32 depth map itself and has no basis images");
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(depth_bias(o)); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  return m;
}

MethodDesc esm_method() {
  MethodDesc m;
  m.name = "esm";
  m.summary = "exponential shadow maps: B = exp(c z), v = exp(-c d) bar(B)";
  m.header = "methods/esm.clh";
  m.channel_count = [](const FilterOptions&) { return 1; };
  m.parameters = "--esm-c C (default 80; limit 174 in f32, 22 in f16)";
  m.storages = "f32 f16";
  m.validate = [st = m.storages](const FilterOptions& o) {
    check_storage("esm", st, o, "exp(c z) is unbounded, so unorm cannot hold it");
    if (!std::isfinite(o.esm.c) || o.esm.c <= 0.0f)
      throw InputError("FilterOptions::esm.c must be a positive number, got " + std::to_string(o.esm.c));
    const bool half = o.storage == Storage::F16;
    const float limit = half ? kEsmMaxCFloat16 : kEsmMaxCFloat32;
    if (o.esm.c > limit) {
      std::ostringstream s;
      s << "FilterOptions::esm.c " << o.esm.c << " exceeds the " << (half ? "float16" : "float32") << " limit of "
        << limit << (half ? " (exp(c/2) must stay below 65504, the largest half)"
                          : " (exp(c/2) must stay a normal float)");
      throw InputError(s.str());
    }
  };
  m.pack_params = [](const FilterOptions& o) { return bytes_of(o.esm.c); };
  m.defines = [](const FilterOptions&) { return std::string(); };
  return m;
}

void validate_vsm_common(const FilterOptions& o) {
  require_finite(o.vsm.min_variance, "FilterOptions::vsm.min_variance");
  if (o.vsm.min_variance == 0.0f)
    throw InputError("FilterOptions::vsm.min_variance must be positive (negative = the default)");
  if (!(o.vsm.lbr >= 0.0f && o.vsm.lbr < 1.0f))
    throw InputError("FilterOptions::vsm.lbr must be in [0, 1), got " + num(o.vsm.lbr));
}

MethodDesc vsm_method() {
  MethodDesc m;
  m.name = "vsm";
  m.summary = "variance shadow maps: B = (z, z^2), one-sided Chebyshev bound";
  m.header = "methods/vsm.clh";
  m.channel_count = [](const FilterOptions&) { return 2; };
  m.parameters = "--vsm-min-variance V (default 2e-5), --lbr A (default 0)";
  m.storages = "f32 f16 unorm16";
  m.validate = [st = m.storages](const FilterOptions& o) {
    check_storage("vsm", st, o, "8-bit steps of z^2 (1/255) are larger than the variances it needs");
    validate_vsm_common(o);
  };
  m.pack_params = [](const FilterOptions& o) {
    struct {
      float min_variance, lbr;
    } p{o.vsm.min_variance > 0 ? o.vsm.min_variance : 2e-5f, o.vsm.lbr};
    return bytes_of(p);
  };
  m.defines = [](const FilterOptions&) { return std::string(); };
  return m;
}

MethodDesc evsm_method(int channels) {
  MethodDesc m;
  m.name = channels == 4 ? "evsm4" : "evsm2";
  m.summary = channels == 4 ? "exponential variance shadow maps, positive and negative warps"
                            : "exponential variance shadow maps, positive warp only";
  m.header = "methods/evsm.clh";
  m.channel_count = [channels](const FilterOptions&) { return channels; };
  m.parameters = std::string("--evsm-pos C+ (default 40") + (channels == 4 ? "), --evsm-neg C- (default 5" : "") +
                 "; clamped to 42 in f32, 5.54 in f16), --vsm-min-variance V (default 1e-4 f32, "
                 "2e-3 f16), --lbr A (default 0)";
  m.storages = "f32 f16";
  m.validate = [name = m.name, st = m.storages](const FilterOptions& o) {
    check_storage(name, st, o, "exp(c w) spans e^-c..e^c, which unorm cannot resolve");
    validate_vsm_common(o);
    if (!(o.evsm.pos > 0.0f) || !std::isfinite(o.evsm.pos) || !(o.evsm.neg > 0.0f) ||
        !std::isfinite(o.evsm.neg))
      throw InputError("FilterOptions::evsm.pos and FilterOptions::evsm.neg must be positive numbers");
  };
  m.pack_params = [](const FilterOptions& o) {
    const float limit = evsm_limit(o.storage);
    const float vmin = o.vsm.min_variance > 0 ? o.vsm.min_variance
                                              : (o.storage == Storage::F16 ? 2e-3f : 1e-4f);
    struct {
      float pos, neg, min_variance, lbr;
    } p{std::min(o.evsm.pos, limit), std::min(o.evsm.neg, limit), vmin, o.vsm.lbr};
    return bytes_of(p);
  };
  m.defines = [](const FilterOptions&) { return std::string(); };
  return m;
}

float msm_moment_bias(const FilterOptions& o) {
  if (o.msm.moment_bias >= 0) return o.msm.moment_bias;
  return o.storage == Storage::F32 ? 3e-6f : 6e-5f;
}

MethodDesc msm_method(bool hausdorff) {
  MethodDesc m;
  m.name = hausdorff ? "msm-hausdorff" : "msm";
  m.summary = hausdorff ? "moment shadow maps, 4 moments, Hausdorff (bounded support [0,1])"
                        : "moment shadow maps, 4 moments, Hamburger (Peters & Klein 2015)";
  m.header = "methods/msm.clh";
  m.channel_count = [](const FilterOptions&) { return 4; };
  m.parameters = "--msm-bias A (default 3e-6 f32, 6e-5 unorm16), --bias B (default 0 f32, "
                 "measured for unorm16)";
  m.storages = "f32 unorm16";
  m.validate = [name = m.name, st = m.storages](const FilterOptions& o) {
    check_storage(name, st, o,
                  "16 bits need the optimised quantisation, which unorm16 resolves 32x finer than "
                  "f16 on [0,1]; 8 bits are far too coarse for 4 moments");
    require_finite(o.msm.moment_bias, "FilterOptions::msm.moment_bias");
    require_finite(depth_bias(o), "FilterOptions::depth_test.bias");
    if (o.msm.moment_bias > 1.0f) throw InputError("FilterOptions::msm.moment_bias must be at most 1");
  };
  m.pack_params = [](const FilterOptions& o) {
    struct {
      float moment_bias, depth_bias;
    } p{msm_moment_bias(o), depth_bias(o)};
    return bytes_of(p);
  };
  m.defines = [](const FilterOptions&) { return std::string(); };
  return m;
}

// Measured defaults (docs/methods.md "CSM defaults", tests/test_methods_csm.cpp): per order an
// offset and scale that keep every lit receiver >= 1 - 1/255 on the bundled spheres and contact
// scenes (R = 3), chosen jointly over the orders so that the error against s_ref (RMSE and p99,
// both scenes) falls by at least 2% from each order to the next, M = 1 .. 32.
struct CsmDefault {
  int order;
  float offset, scale;
};
const CsmDefault kCsmDefaults[] = {
    {1, 0.12f, 1.4f},   {2, 0.05f, 1.5f},     {4, 0.0075f, 2.0f},
    {8, 0.02f, 1.4f},   {16, 0.0225f, 1.05f}, {32, 0.0175f, 1.0f},
};

// msm in unorm16: the smallest depth bias that keeps every flat receiver lit (docs/methods.md,
// test MsmUnormBias).
// Measured (DISABLED_Measure): 1e-5 is the least that works for z = k/256; 1e-4 keeps a 10x margin
// and stays below 5e-4, where Hausdorff's [0,1] support starts to cut off receivers near z = 0.
constexpr float kMsmUnorm16DepthBias = 1e-4f;

}  // namespace

float depth_bias(const FilterOptions& o) {
  if (o.depth_test.bias) return *o.depth_test.bias;
  if (o.method.rfind("msm", 0) == 0 && o.storage == Storage::Unorm16) return kMsmUnorm16DepthBias;
  return 0.0f;
}

CsmParameters csm_parameters(const FilterOptions& o) {
  // Orders between measured ones take the next lower measured order's values (larger offset:
  // still lit, a little more shadow displacement).
  CsmDefault d = kCsmDefaults[0];
  for (const auto& e : kCsmDefaults)
    if (e.order <= o.csm.order) d = e;
  CsmParameters p;
  p.alpha = o.csm.alpha;
  p.offset = o.csm.offset >= 0 ? o.csm.offset : d.offset;
  p.scale = o.csm.scale >= 0 ? o.csm.scale : d.scale;
  return p;
}

namespace {

MethodDesc csm_method() {
  MethodDesc m;
  m.name = "csm";
  m.summary = "convolution shadow maps: Fourier basis sin/cos((2k-1) pi z), k = 1..M";
  m.header = "methods/csm.clh";
  m.channel_count = [](const FilterOptions& o) { return 2 * o.csm.order; };
  m.parameters =
      "--csm-order M (1..32, default 8), --csm-alpha A (default 0), --csm-offset O and "
      "--csm-scale S (default: measured per order, docs/methods.md)";
  m.storages = "f32 f16 unorm16 unorm8";
  m.validate = [st = m.storages](const FilterOptions& o) {
    check_storage("csm", st, o, "");
    if (o.csm.order < 1 || o.csm.order > kCsmMaxOrder)
      throw InputError("FilterOptions::csm.order must be in 1.." + std::to_string(kCsmMaxOrder) + ", got " +
                       std::to_string(o.csm.order));
    require_finite(o.csm.alpha, "FilterOptions::csm.alpha");
    require_finite(o.csm.offset, "FilterOptions::csm.offset");
    require_finite(o.csm.scale, "FilterOptions::csm.scale");
    if (o.csm.alpha < 0) throw InputError("FilterOptions::csm.alpha must be >= 0");
    if (o.csm.offset > 1.0f) throw InputError("FilterOptions::csm.offset must be at most 1 (negative = default)");
  };
  m.pack_params = [](const FilterOptions& o) {
    const CsmParameters c = csm_parameters(o);
    struct {
      float alpha, offset, scale;
    } p{c.alpha, c.offset, c.scale};
    return bytes_of(p);
  };
  m.defines = [](const FilterOptions& o) { return " -DSF_CSM_ORDER=" + std::to_string(o.csm.order); };
  return m;
}

}  // namespace

const std::vector<MethodDesc>& methods() {
  static const std::vector<MethodDesc> all = {
      raw_depth_method("sm", "plain shadow-map test H(z - d + b) under the bilinear weights"),
      raw_depth_method("pcf",
                       "percentage-closer filtering: H(z - d + b) brute force under the "
                       "prefilter's weights (Gaussian (x) bilinear), i.e. s_ref"),
      esm_method(),
      vsm_method(),
      evsm_method(2),
      evsm_method(4),
      msm_method(false),
      msm_method(true),
      csm_method(),
  };
  return all;
}

size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o) {
  return size_t(m.channels(o)) * (m.raw_depth ? 4 : storage_bytes(o.storage));
}

const MethodDesc& find_method(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : methods()) known += (known.empty() ? "" : ", ") + m.name;
  throw InputError("unknown method '" + name + "' (known: " + known + ")");
}

}  // namespace sf

// Figures of docs/soft.md (sf_measure, run by scripts/soft_figures.sh; not part of the test suite).
//   SF_SOFT_SCENES="dir dir ..." sf_measure --gtest_also_run_disabled_tests --gtest_filter='SoftFigures.*'
// Every scene dir holds shadowmap.exr (the light in its header), receivers.exr, reference_soft.exr.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <vector>

#include "image_io.hpp"
#include "lookups.hpp"
#include "scene_light.hpp"
#include "soft_reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::test {
namespace {

struct Scene {
  std::string name;
  HostImage depth, ref;
  Receivers rx;
  SoftLight light;
};

Scene load(const std::string& dir) {
  Scene s;
  s.name = dir.substr(dir.find_last_of('/') + 1);
  s.depth = io::load_depth_map(dir + "/shadowmap.exr", {});
  s.rx = io::load_receiver_image(dir + "/receivers.exr");
  s.ref = io::load_depth_map(dir + "/reference_soft.exr", {});
  s.light = header_light(dir + "/shadowmap.exr");
  return s;
}

struct Device {
  cl::Buffer depth, u, v, d, f, out;
  size_t n = 0;
  DeviceReceivers rx() const {
    DeviceReceivers r;
    r.count = n;
    r.u = u, r.v = v, r.d = d, r.f = f;
    return r;
  }
};
Device upload(const Scene& s) {
  Device D;
  D.n = s.rx.count();
  D.depth = to_device(s.depth.data);
  D.u = to_device(s.rx.u);
  D.v = to_device(s.rx.v);
  D.d = to_device(s.rx.d);
  if (s.rx.has_footprint) D.f = to_device(s.rx.f);
  D.out = to_device(std::vector<float>(D.n, 0.0f));
  return D;
}

// Median wall seconds of prepare + run (queue drained) over `runs` after one warm-up.
double time_method(SoftFilter& F, const Device& D, int runs = 3) {
  std::vector<double> t;
  for (int r = 0; r <= runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    cl::Event e = F.prefilter(D.depth);
    EventList after{e};
    F.reconstruct(D.rx(), D.out, &after);
    runtime().queue().finish();
    if (r) t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

struct Variant {
  const char* label;
  SoftMethod m;
  int order;
  Lookup lookup;
};
const Variant kVariants[] = {
    {"pcss", SoftMethod::Pcss, 4, Lookup::Sat},
    {"cssm M=4 mips", SoftMethod::Cssm, 4, Lookup::Mips},
    {"cssm M=4 sat", SoftMethod::Cssm, 4, Lookup::Sat},
    {"cssm M=16 mips", SoftMethod::Cssm, 16, Lookup::Mips},
    {"cssm M=16 sat", SoftMethod::Cssm, 16, Lookup::Sat},
    {"ssmm", SoftMethod::Ssmm, 4, Lookup::Sat},
    {"ssmm-improved", SoftMethod::SsmmImproved, 4, Lookup::Sat},
};

std::vector<std::string> scene_dirs() {
  std::vector<std::string> v;
  const char* e = std::getenv("SF_SOFT_SCENES");
  std::istringstream in(e ? e : "");
  std::string s;
  while (in >> s) v.push_back(s);
  return v;
}

// Every scene dir, loaded and on the device.
struct SceneSet {
  std::vector<Scene> scenes;
  std::vector<Device> dev;
};
SceneSet load_scenes() {
  SceneSet S;
  for (const std::string& dir : scene_dirs()) {
    S.scenes.push_back(load(dir));
    S.dev.push_back(upload(S.scenes.back()));
  }
  return S;
}

// The integers of environment variable `name`, else of `fallback` ("2 3 4").
std::vector<int> int_list(const char* name, const char* fallback) {
  const char* e = std::getenv(name);
  std::istringstream in(e ? e : fallback);
  std::vector<int> v;
  for (int n; in >> n;) v.push_back(n);
  return v;
}

// A visibility against the scene's reference over its non-background receivers: RMSE, p99 of
// |err|, mean signed error, and how many were not finite (none may be).
struct Errors {
  double rmse = 0, p99 = 0, mean = 0;
  size_t nonfinite = 0;
};
Errors errors(const Scene& s, const std::vector<float>& vis) {
  std::vector<double> err;
  double se = 0, sum = 0;
  Errors r;
  for (size_t i = 0; i < vis.size(); ++i) {
    if (!std::isfinite(s.rx.d[i])) continue;
    r.nonfinite += !std::isfinite(vis[i]);
    const double e = vis[i] - s.ref.data[i];
    err.push_back(std::abs(e));
    se += e * e;
    sum += e;
  }
  std::sort(err.begin(), err.end());
  r.rmse = std::sqrt(se / err.size());
  r.p99 = err[size_t(0.99 * (err.size() - 1))];
  r.mean = sum / err.size();
  return r;
}

// A visibility against a baseline one (float32's) over the scene's non-background receivers,
// summed over scenes: the RMS and the largest |difference|.
struct Difference {
  double sum_sq = 0, max = 0;
  size_t n = 0;
  void add(const Scene& s, const std::vector<float>& vis, const std::vector<float>& base) {
    for (size_t i = 0; i < vis.size(); ++i) {
      if (!std::isfinite(s.rx.d[i])) continue;
      const double y = double(vis[i]) - base[i];
      sum_sq += y * y;
      max = std::max(max, std::abs(y));
      ++n;
    }
  }
  double rms() const { return std::sqrt(sum_sq / n); }
};

TEST(SoftFigures, QualityAndTime) {
  std::printf("| scene | light | L | method | RMSE | p99 abs err | mean err | ms (prepare + run) | ns / receiver |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& dir : scene_dirs()) {
    const Scene s = load(dir);
    const Device D = upload(s);
    size_t fg = 0;
    for (float d : s.rx.d) fg += std::isfinite(d);
    for (const Variant& V : kVariants) {
      // SF_SOFT_ONLY=label restricts the variants; SF_SOFT_CSSM_OFFSET / _SCALE / ... / _STORAGE
      // override cssm's.
      if (const char* only = std::getenv("SF_SOFT_ONLY"); only && std::string(only) != V.label) continue;
      SoftOptions o;
      o.method = V.m;
      o.cssm.order = V.order;
      o.cssm.lookup = V.lookup;
      o.light = s.light;
      if (const char* e = std::getenv("SF_SOFT_CSSM_OFFSET")) o.cssm.offset = float(std::atof(e));
      if (const char* e = std::getenv("SF_SOFT_CSSM_SCALE")) o.cssm.scale = float(std::atof(e));
      if (const char* e = std::getenv("SF_SOFT_CSSM_ZOFFSET")) o.cssm.z_offset = float(std::atof(e));
      if (const char* e = std::getenv("SF_SOFT_CSSM_WSCALE")) o.cssm.width_scale = float(std::atof(e));
      if (const char* e = std::getenv("SF_SOFT_CSSM_CONTACT")) o.cssm.contact = std::atoi(e) != 0;
      if (const char* e = std::getenv("SF_SOFT_CSSM_SHARPEN_A")) o.cssm.sharpen_a = float(std::atof(e));
      if (const char* e = std::getenv("SF_SOFT_CSSM_STORAGE")) o.cssm.storage = parse_storage(e);
      SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
      const double sec = time_method(F, D, 1);
      const Errors E = errors(s, from_device(D.out, D.n));
      ASSERT_EQ(E.nonfinite, 0u);
      std::printf("| %s | %s | %.3g | %s | %.4f | %.3f | %+.4f | %.1f | %.0f |\n", s.name.c_str(),
                  s.light.perspective ? "persp" : "ortho", s.light.size, V.label, E.rmse, E.p99, E.mean, sec * 1e3,
                  sec * 1e9 / fg);
    }
  }
}

// cssm parameter sweep (the table of docs/soft.md that chose the defaults): every scene dir, one
// line per setting of SF_SOFT_SWEEP="M,lookup,offset,scale,z_offset,width_scale,contact,A,B,normalise;..."
// (lookup m or s; negative values: the defaults of SoftOptions), RMSE and p99 |err| per scene and their means.
TEST(SoftFigures, CssmSweep) {
  const auto [scenes, dev] = load_scenes();
  ASSERT_FALSE(scenes.empty());
  const char* e = std::getenv("SF_SOFT_SWEEP");
  ASSERT_TRUE(e) << "set SF_SOFT_SWEEP";
  std::printf("| M | lookup | offset | scale | z_offset | width x | contact | A,B | normalise |");
  for (const Scene& s : scenes) std::printf(" %s RMSE / p99 |", s.name.c_str());
  std::printf(" mean RMSE | mean p99 |\n");
  std::istringstream all(e);
  std::string line;
  while (std::getline(all, line, ';')) {
    if (line.find_first_not_of(" \n") == std::string::npos) continue;
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream in(line);
    int M = 4, contact = 1, norm = 1;
    char lk = 'm';
    float off = -1, sc = -1, zo = -1, ws = -1, A = 30, B = -1;
    in >> M >> lk >> off >> sc >> zo >> ws >> contact >> A >> B >> norm;
    std::printf("| %d | %s | %.4g | %.3g | %.4g | %.3g | %d | %.3g,%.3g | %d |", M, lk == 's' ? "sat" : "mips", off, sc,
                zo, ws, contact, A, B, norm);
    double mr = 0, mp = 0;
    for (size_t k = 0; k < scenes.size(); ++k) {
      const Scene& s = scenes[k];
      SoftOptions o;
      o.method = SoftMethod::Cssm;
      o.cssm.order = M;
      o.cssm.lookup = lk == 's' ? Lookup::Sat : Lookup::Mips;
      o.cssm.offset = off;
      o.cssm.scale = sc;
      o.cssm.z_offset = zo;
      o.cssm.width_scale = ws;
      o.cssm.contact = contact != 0;
      o.cssm.sharpen_a = A;
      o.cssm.sharpen_b = B;
      o.cssm.normalise = norm != 0;
      o.light = s.light;
      try {
        validate(o);
      } catch (const InputError& x) {
        std::printf(" refused: %s |", x.what());
        break;
      }
      SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
      cl::Event ev = F.prefilter(dev[k].depth);
      EventList after{ev};
      F.reconstruct(dev[k].rx(), dev[k].out, &after);
      const Errors E = errors(s, from_device(dev[k].out, dev[k].n));
      mr += E.rmse / scenes.size();
      mp += E.p99 / scenes.size();
      std::printf(" %.4f / %.3f |", E.rmse, E.p99);
    }
    std::printf(" %.4f | %.3f |\n", mr, mp);
    std::fflush(stdout);
  }
}

// ssmm's kernel size n swept (Shen 2016 sec. 4.1.3, fig. 4.4: n = 2, 5, 9; SF_SSMM_N="2 3 ..."
// overrides the list), ssmm and ssmm-improved, every scene dir: RMSE per scene and over the
// scenes the mean RMSE, mean p99 |err|, mean signed error, the mean visibility where the
// reference is umbra (<= 0.02: the seed's large n lights the umbra) and the mean time.
TEST(SoftFigures, SsmmSweep) {
  const auto [scenes, dev] = load_scenes();
  ASSERT_FALSE(scenes.empty());
  const std::vector<int> ns = int_list("SF_SSMM_N", "2 3 4 5 6 9");
  std::printf("| method | n |");
  for (const Scene& s : scenes) std::printf(" %s |", s.name.c_str());
  std::printf(" mean RMSE | mean p99 | mean err | umbra v | ms |\n|---|---|");
  for (size_t k = 0; k < scenes.size() + 5; ++k) std::printf("---|");
  std::printf("\n");
  for (const SoftMethod m : {SoftMethod::Ssmm, SoftMethod::SsmmImproved}) {
    for (const int n : ns) {
      std::printf("| %s | %d |", soft_method_name(m), n);
      double mr = 0, mp = 0, me = 0, ms = 0, umbra = 0;
      size_t umbra_n = 0;
      for (size_t k = 0; k < scenes.size(); ++k) {
        const Scene& s = scenes[k];
        SoftOptions o;
        o.method = m;
        o.ssmm.n = n;
        o.light = s.light;
        SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
        ms += time_method(F, dev[k], 1) * 1e3 / scenes.size();
        const std::vector<float> vis = from_device(dev[k].out, dev[k].n);
        const Errors E = errors(s, vis);
        ASSERT_EQ(E.nonfinite, 0u);
        for (size_t i = 0; i < vis.size(); ++i)
          if (std::isfinite(s.rx.d[i]) && s.ref.data[i] <= 0.02f) umbra += vis[i], ++umbra_n;
        mr += E.rmse / scenes.size();
        mp += E.p99 / scenes.size();
        me += E.mean / scenes.size();
        std::printf(" %.4f |", E.rmse);
      }
      std::printf(" %.4f | %.3f | %+.4f | %.3f | %.1f |\n", mr, mp, me, umbra_n ? umbra / umbra_n : 0.0, ms);
      std::fflush(stdout);
    }
  }
}

// cssm's basis in each storage (mips; with mip-maps Annen 2008 sec. 8.4 stores the CSM planes in
// 8 bits, the CSM-Z planes in 16), M = 4 and 16 (SF_CSSM_ORDERS overrides), every scene dir:
// against the ray-traced reference the mean RMSE and mean p99 |err| over the scenes; against
// float32's visibility the RMSE and the largest |difference| over all receivers; the basis and
// chain's bytes and the mean time.
TEST(SoftFigures, CssmStorage) {
  const auto [scenes, dev] = load_scenes();
  ASSERT_FALSE(scenes.empty());
  const std::vector<int> orders = int_list("SF_CSSM_ORDERS", "4 16");
  std::printf(
      "| M | storage | mean RMSE | mean p99 | RMSE against f32 | max abs diff against f32 | MiB (basis + chain, "
      "%dx%d) | ms |\n|---|---|---|---|---|---|---|---|\n",
      scenes[0].depth.width, scenes[0].depth.height);
  for (const int M : orders) {
    std::vector<std::vector<float>> f32(scenes.size());
    for (const Storage st : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
      double mr = 0, mp = 0, ms = 0;
      size_t bytes = 0;
      Difference against_f32;
      std::string refused;
      for (size_t k = 0; k < scenes.size(); ++k) {
        const Scene& s = scenes[k];
        SoftOptions o;
        o.method = SoftMethod::Cssm;
        o.cssm.order = M;
        o.cssm.lookup = Lookup::Mips;
        o.cssm.storage = st;
        o.light = s.light;
        try {
          validate(o);
        } catch (const InputError& x) {  // unorm8: docs/soft.md says how its row was measured
          refused = x.what();
          break;
        }
        SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
        if (k == 0) bytes = F.device_bytes();
        ms += time_method(F, dev[k], 1) * 1e3 / scenes.size();
        const std::vector<float> vis = from_device(dev[k].out, dev[k].n);
        if (st == Storage::F32) f32[k] = vis;
        const Errors E = errors(s, vis);
        ASSERT_EQ(E.nonfinite, 0u);
        against_f32.add(s, vis, f32[k]);
        mr += E.rmse / scenes.size();
        mp += E.p99 / scenes.size();
      }
      if (!refused.empty()) {
        std::printf("| %d | %s | refused: %s |\n", M, storage_name(st), refused.c_str());
        continue;
      }
      std::printf("| %d | %s | %.4f | %.3f | %.4f | %.3f | %.1f | %.1f |\n", M, storage_name(st), mr, mp,
                  against_f32.rms(), against_f32.max, bytes / 1048576.0, ms);
      std::fflush(stdout);
    }
  }
}

// The seed's mix (Annen 2008 sec. 8.4: the 2M CSM planes in 8 bits, the CSM-Z planes and the
// constant in 16), measured through the double reference (soft_cssm over a LookupRef whose mip
// levels round each plane as its storage holds it) beside every plane in unorm16 and in unorm8,
// each against the reference's float32 visibility (RMSE, largest |difference|) and against the
// ray-traced reference (mean RMSE over the scenes); mips, M = 4 and 16 (SF_CSSM_ORDERS).
TEST(SoftFigures, CssmStorageMix) {
  const auto [scenes, dev] = load_scenes();
  ASSERT_FALSE(scenes.empty());
  const std::vector<int> orders = int_list("SF_CSSM_ORDERS", "4 16");
  std::printf(
      "| M | storage (double reference) | mean RMSE | RMSE against f32 | max abs diff against f32 |\n"
      "|---|---|---|---|---|\n");
  for (const int M : orders) {
    std::vector<std::vector<float>> f32(scenes.size());
    for (const char* variant : {"f32", "unorm16", "unorm8", "unorm8 CSM + unorm16 CSM-Z"}) {
      const std::string name = variant;
      double mean_rmse = 0;
      Difference against_f32;
      for (size_t k = 0; k < scenes.size(); ++k) {
        const Scene& sc = scenes[k];
        SoftOptions o;
        o.method = SoftMethod::Cssm;
        o.cssm.order = M;
        o.cssm.lookup = Lookup::Mips;
        o.cssm.storage = name == "f32" ? Storage::F32 : Storage::Unorm16;  // unorm: every plane decoded 2 x - 1
        o.light = sc.light;
        std::vector<Storage> per_plane(4 * M + 1, Storage::Unorm16);
        ref::Planes basis = ref::cssm_basis(sc.depth, M, o.cssm.storage);
        if (name == "unorm8" || name.rfind("unorm8 CSM", 0) == 0) {
          const ref::Planes eight = ref::cssm_basis(sc.depth, M, Storage::Unorm8);
          const int narrow = name == "unorm8" ? 4 * M + 1 : 2 * M;  // planes stored in 8 bits
          const size_t plane = size_t(basis.width) * basis.height;
          std::copy(eight.data.begin(), eight.data.begin() + narrow * plane, basis.data.begin());
          std::fill(per_plane.begin(), per_plane.begin() + narrow, Storage::Unorm8);
        }
        if (name == "f32") std::fill(per_plane.begin(), per_plane.end(), Storage::F32);
        const ref::LookupRef lookup(basis, Lookup::Mips, per_plane);
        std::vector<float> vis(sc.rx.count(), 1.0f);
        for (size_t i = 0; i < vis.size(); ++i) {
          if (!std::isfinite(sc.rx.d[i])) continue;
          vis[i] = float(ref::soft_cssm(lookup, sc.depth.width, sc.depth.height, o, sc.rx.u[i], sc.rx.v[i], sc.rx.d[i],
                                        ref::soft_footprint(sc.rx, i)));
        }
        if (name == "f32") f32[k] = vis;
        mean_rmse += errors(sc, vis).rmse / scenes.size();
        against_f32.add(sc, vis, f32[k]);
      }
      std::printf("| %d | %s | %.4f | %.4f | %.3f |\n", M, variant, mean_rmse, against_f32.rms(), against_f32.max);
      std::fflush(stdout);
    }
  }
}

// Time per receiver against light size (first scene dir): cssm's must stay flat, pcss's grows.
TEST(SoftFigures, CostAgainstLightSize) {
  const auto dirs = scene_dirs();
  ASSERT_FALSE(dirs.empty());
  const Scene s = load(dirs.front());
  const Device D = upload(s);
  size_t fg = 0;
  for (float d : s.rx.d) fg += std::isfinite(d);
  std::printf(
      "| method | L = 0.05 | 0.1 | 0.2 | 0.4 | 0.8 | (reconstruction ns per receiver, %s, %zu receivers) "
      "|\n|---|---|---|---|---|---|---|\n",
      s.name.c_str(), fg);
  for (const Variant& V : kVariants) {
    std::printf("| %s |", V.label);
    std::vector<double> t;
    for (double L : {0.05, 0.1, 0.2, 0.4, 0.8}) {
      SoftOptions o;
      o.method = V.m;
      o.cssm.order = V.order;
      o.cssm.lookup = V.lookup;
      o.light = s.light;
      o.light.size = L;
      if (V.m == SoftMethod::Cssm && V.order == 16 && V.lookup == Lookup::Sat) continue;  // minutes
      SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
      time_method(F, D, 2);
      t.push_back(F.times().reconstruct * 1e9 / fg);  // last run's reconstruction, device time
      std::printf(" %.0f |", t.back());
    }
    if (!t.empty()) std::printf(" ratio 0.8/0.05 = %.2f", t.back() / t.front());
    std::printf("\n");
  }
}

// Rectangular lights (Annen 2008 sec. 8.5; issue: "within the RMSE they reach for square lights
// of the same area"): every scene dir (generated with `scene --light-size W,H` at several aspect
// ratios of one area), each method's RMSE against the ray-traced reference of its own light, per
// scene, then the mean over the scenes of each aspect ratio W / H.
TEST(SoftFigures, RectangularLights) {
  const auto [scenes, dev] = load_scenes();
  ASSERT_FALSE(scenes.empty());
  std::map<double, std::map<std::string, std::vector<double>>> by_aspect;
  std::map<double, std::map<std::string, std::vector<double>>> ms_by_aspect;
  std::printf("| scene | light W x H | method | RMSE | ms |\n|---|---|---|---|---|\n");
  for (size_t k = 0; k < scenes.size(); ++k) {
    const Scene& s = scenes[k];
    const double aspect = s.light.size / light_height(s.light);
    for (const Variant& V : kVariants) {
      if (V.m == SoftMethod::Cssm && V.order == 16) continue;
      SoftOptions o;
      o.method = V.m;
      o.cssm.order = V.order;
      o.cssm.lookup = V.lookup;
      o.light = s.light;
      SoftFilter F(runtime_ptr(), o, s.depth.width, s.depth.height);
      const double sec = time_method(F, dev[k], 1);
      const Errors E = errors(s, from_device(dev[k].out, dev[k].n));
      ASSERT_EQ(E.nonfinite, 0u);
      by_aspect[aspect][V.label].push_back(E.rmse);
      ms_by_aspect[aspect][V.label].push_back(sec * 1e3);
      std::printf("| %s | %.3g x %.3g | %s | %.4f | %.0f |\n", s.name.c_str(), s.light.size, light_height(s.light),
                  V.label, E.rmse, sec * 1e3);
    }
  }
  std::printf("\n| W / H | scenes |");
  for (const Variant& V : kVariants)
    if (!(V.m == SoftMethod::Cssm && V.order == 16)) std::printf(" %s RMSE (ms) |", V.label);
  std::printf("\n|---|---|---|---|---|---|---|\n");
  for (const auto& [aspect, methods] : by_aspect) {
    std::printf("| %.3g | %zu |", aspect, methods.begin()->second.size());
    for (const Variant& V : kVariants) {
      if (V.m == SoftMethod::Cssm && V.order == 16) continue;
      const std::vector<double>& r = methods.at(V.label);
      const std::vector<double>& t = ms_by_aspect[aspect][V.label];
      double mr = 0, mt = 0;
      for (size_t i = 0; i < r.size(); ++i) mr += r[i] / r.size(), mt += t[i] / t.size();
      std::printf(" %.4f (%.0f) |", mr, mt);
    }
    std::printf("\n");
  }
}

// Frame time against the number of lights (Annen 2008 table 8.1): N lights, each its own map
// (the first scene's map, uploaded N times), prepare + run per light, one frame = all of them.
TEST(SoftFigures, LightCount) {
  const auto dirs = scene_dirs();
  ASSERT_FALSE(dirs.empty());
  const Scene s = load(dirs.front());
  std::printf("| method (%dx%d map, %dx%d receivers) | 1 light | 10 | 20 | 40 |\n|---|---|---|---|---|\n",
              s.depth.width, s.depth.height, s.rx.width, s.rx.height);
  for (const Variant& V : kVariants) {
    if (V.m == SoftMethod::Cssm && V.order == 16) continue;  // M = 4 as in table 8.1
    std::printf("| %s |", V.label);
    for (int N : {1, 10, 20, 40}) {
      SoftOptions o;
      o.method = V.m;
      o.cssm.order = V.order;
      o.cssm.lookup = V.lookup;
      o.light = s.light;
      std::vector<std::unique_ptr<SoftFilter>> F;
      std::vector<Device> D;
      for (int i = 0; i < N; ++i) {
        F.push_back(std::make_unique<SoftFilter>(runtime_ptr(), o, s.depth.width, s.depth.height));
        D.push_back(upload(s));
      }
      auto frame = [&] {
        for (int i = 0; i < N; ++i) {
          cl::Event e = F[i]->prefilter(D[i].depth);
          EventList after{e};
          F[i]->reconstruct(D[i].rx(), D[i].out, &after);
        }
        runtime().queue().finish();
      };
      if (N == 1) frame();  // warm-up (program builds)
      const auto t0 = std::chrono::steady_clock::now();
      frame();
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf(" %.2f fps (%.0f ms) |", 1.0 / sec, sec * 1e3);
      std::fflush(stdout);
    }
    std::printf("\n");
  }
}

}  // namespace
}  // namespace sf::test

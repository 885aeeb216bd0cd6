#pragma once
// The bundled scenes as CSM's tests and measurements read them: planar receivers, s_ref, and a
// run that prefilters once per order and reconstructs for any offset and scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "image_io.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/pipeline.hpp"
#include "test_methods_common.hpp"

namespace sf::test::csm_scenes {

inline constexpr int kRadius = 3;  // Gaussian prefilter of the measurement
inline const char* const kScenes[] = {"spheres", "contact"};
inline constexpr int kOrders[] = {1, 2, 4, 8, 16, 32};
inline constexpr float kLitTolerance = 0.01f;  // texels this close in front of a receiver: its surface

// A bundled scene's planar receivers (one per shadow-map texel, on the ground plane) with s_ref
// at R = 3 and a classification: lit = every texel the lookup can touch lies at most 0.01 in
// front of the receiver (only its own surface is there; as in test_esm_scene.cpp), and none is
// empty map (z = 1, the far plane). Receivers next to empty map are left out of both sets: there
// z - d reaches 1 - d, and the period-2 basis reads z - d + offset >= 1 as shadow (csm's wrap,
// docs/methods.md) whatever the order; the floor's edge near the light has d down to 0.01.
struct CsmScene {
  HostImage depth;
  Receivers rx;
  std::vector<double> sref;
  std::vector<char> lit, scored;  // scored: finite d, not lit, not next to empty map
  size_t n_lit = 0, n_scored = 0, n_edge = 0;
};

inline CsmScene load_csm_scene(const std::string& name) {
  CsmScene c;
  c.depth = io::load_depth_map(data_path(name + "/shadowmap.exr"), {});
  c.rx = io::load_receiver_depth(data_path(name + "/receiver_depth.exr"), c.depth.width, c.depth.height, {});
  // The reference is s_ref of the receiver moved kLitTolerance toward the light: the receiver's
  // own surface, sloped in light space, counts as lit there as in the lit set (with d itself
  // about half of a sloped floor's footprint lies in front, and that self-shadow, the same for
  // every order, dominated the error).
  Receivers moved = c.rx;
  for (float& d : moved.d) d -= kLitTolerance;
  c.sref = ref::s_ref(c.depth, BlurOptions{kRadius, 0.0f}, moved);
  const int W = c.depth.width, H = c.depth.height;
  c.lit.assign(c.rx.count(), 0);
  c.scored.assign(c.rx.count(), 0);
  for (size_t i = 0; i < c.rx.count(); ++i) {
    const float d = c.rx.d[i];
    if (!std::isfinite(d)) continue;
    const int px = int(i % W), py = int(i / W);
    bool all_lit = true, edge = false;
    for (int y = py - kRadius - 1; y <= py + kRadius + 1; ++y)
      for (int x = px - kRadius - 1; x <= px + kRadius + 1; ++x) {
        const float z = c.depth.at(std::clamp(x, 0, W - 1), std::clamp(y, 0, H - 1));
        all_lit &= z >= d - kLitTolerance;
        edge |= z >= 1.0f;
      }
    if (edge) {
      ++c.n_edge;
      continue;
    }
    c.lit[i] = all_lit;
    c.scored[i] = !all_lit;
    c.n_lit += all_lit;
    c.n_scored += !all_lit;
  }
  return c;
}

inline const CsmScene& csm_scene(int k) {
  static const CsmScene scenes[] = {load_csm_scene(kScenes[0]), load_csm_scene(kScenes[1])};
  return scenes[k];
}

struct CsmScore {
  float min_lit = 1;  // lowest visibility over lit receivers
  double rmse = 0;    // over the other (shadowed and penumbra) receivers, |v - s_ref|
  double p99 = 0;     // 99th percentile of |v - s_ref| over them
  double mean = 0;
  bool lit_ok() const { return min_lit >= 1.0f - 1.0f / 255.0f; }
};

// Visibility v = min(scale f, 1) from f = the visibility at scale 1 (the kernel's clamp(scale f,
// 0, 1) equals it for scale >= 1 up to the rounding of one product).
inline CsmScore score(const CsmScene& s, const std::vector<float>& f, float scale) {
  CsmScore r;
  std::vector<double> err;
  err.reserve(s.n_scored);
  for (size_t i = 0; i < f.size(); ++i) {
    const float v = std::min(scale * f[i], 1.0f);
    if (s.lit[i]) r.min_lit = std::min(r.min_lit, v);
    if (s.scored[i]) {
      const double e = std::abs(v - s.sref[i]);
      err.push_back(e);
      r.rmse += e * e;
      r.mean += e;
    }
  }
  r.rmse = std::sqrt(r.rmse / double(err.size()));
  r.mean /= double(err.size());
  std::nth_element(err.begin(), err.begin() + err.size() * 99 / 100, err.end());
  r.p99 = err[err.size() * 99 / 100];
  return r;
}

// Prefilters one scene once per order, then reconstructs for any offset and scale (runtime
// parameters).
struct CsmRun {
  const CsmScene& scene;
  FilterOptions opt;
  std::unique_ptr<Pipeline> pipe;
  cl::Buffer d, vis;
  CsmRun(const CsmScene& s, int order) : scene(s) {
    opt.method = "csm";
    opt.csm.order = order;
    opt.blur.radius = kRadius;
    pipe = std::make_unique<Pipeline>(runtime_ptr(), opt, s.depth.width, s.depth.height);
    pipe->prefilter(to_device(s.depth.data)).wait();
    d = to_device(s.rx.d);
    vis = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, s.rx.count() * sizeof(float));
  }
  std::vector<float> visibility(float offset, float scale) {
    FilterOptions o = opt;
    o.csm.offset = offset;
    o.csm.scale = scale;
    enqueue_reconstruct_grid(runtime(), pipe->method(), o, scene.depth.width, scene.depth.height, pipe->basis(), d, vis)
        .wait();
    return from_device(vis, scene.rx.count());
  }
};

}  // namespace sf::test::csm_scenes

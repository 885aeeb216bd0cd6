// The figures of docs/coherent_render.md: render time and samples per second of the CSM render
// against Embree occlusion rays on the same samples (interleaved runs), and the RMSE of both
// against a converged Embree render as samples grow (Figures); the three visibility filters, the
// progressive passes and the glossy BRDF (FiltersPassesGlossy).
//
//   SF_CSM_FILE=/tmp/bunny.csm build/tests/sf_measure --gtest_filter='CoherentRender.*'
//
// The file is what `shadowfilter coherent build` writes (its object from the file's source, or
// SF_CSM_MESH); the environment is data/envmaps/sky.exr. Without SF_CSM_FILE the test is skipped.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "coherent_file.hpp"
#include "coherent_render.hpp"
#include "coherent_stack.hpp"
#include "envmap.hpp"
#include "ray_tracer.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

using namespace sf::scene;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// What both figures render: the stack of SF_CSM_FILE, its object (the file's source, or
// SF_CSM_MESH), the image side (SF_RENDER_SIZE, default 256) and data/envmaps/sky.exr.
struct Measured {
  io::CoherentFile file;
  std::unique_ptr<RayTracer> tracer;
  int size = 256;
  EnvMap env;
  // The G-buffer of the framing camera with one albedo.
  GBuffer gbuffer(const std::array<float, 3>& albedo) const {
    const coherent::StackLayout& l = file.stack.layout;
    const Vec3 center{l.center[0], l.center[1], l.center[2]};
    return render_gbuffer(*tracer, framing_camera(center, l.radius, size, size, 40.0), l.radius, albedo);
  }
};
// Null without SF_CSM_FILE.
std::unique_ptr<Measured> measured() {
  const char* path = std::getenv("SF_CSM_FILE");
  if (!path) return nullptr;
  auto m = std::make_unique<Measured>();
  m->file = io::read_coherent(path);
  const char* mesh = std::getenv("SF_CSM_MESH");
  m->tracer = std::make_unique<RayTracer>(load_coherent_object(mesh ? mesh : m->file.source));
  if (const char* size = std::getenv("SF_RENDER_SIZE")) m->size = std::atoi(size);
  m->env = load_envmap(data_path("envmaps/sky.exr"));
  return m;
}

TEST(CoherentRender, Figures) {
  const std::unique_ptr<Measured> m = measured();
  if (!m) GTEST_SKIP() << "set SF_CSM_FILE to a .csm file";
  const io::CoherentFile& file = m->file;
  const RayTracer& tracer = *m->tracer;
  const coherent::StackLayout& l = file.stack.layout;
  const int size = m->size;
  const EnvMap& env = m->env;
  const GBuffer g = m->gbuffer({0.8f, 0.8f, 0.8f});
  RenderSettings s;
  s.samples = 1024;
  s.seed = 12345;
  const auto t0 = std::chrono::steady_clock::now();
  const HostImage converged = render_traced(tracer, g, env, s);
  const double converged_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%dx%d, %zu pixels on the object, stack %dx%d views M=%d; converged: Embree %d samples, %.1f s\n", size,
              size, g.hits, l.views_theta, l.views_phi, l.resolution, s.samples, converged_s);
  render_coherent(runtime(), file.stack, g, env, s);  // builds the program once, outside the timings
  std::printf(
      "| samples | CSM s | CSM M samples/s | Embree s | Embree M samples/s | speed-up | "
      "RMSE CSM | RMSE Embree (same samples) | RMSE CSM vs Embree |\n|---|---|---|---|---|---|---|---|---|\n");
  s.seed = 1;
  for (int S : {1, 4, 16, 64, 256}) {
    s.samples = S;
    std::vector<double> tc, te;
    HostImage csm, traced;
    for (int run = 0; run < 3; ++run) {  // interleaved: both see the same machine load
      RenderStats k;
      csm = render_coherent(runtime(), file.stack, g, env, s, &k);
      tc.push_back(k.seconds);
      const auto t1 = std::chrono::steady_clock::now();
      traced = render_traced(tracer, g, env, s);
      te.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
    }
    const double q = render_queries(g, env, s), c = median(tc), e = median(te);
    std::printf("| %d | %.3f | %.1f | %.3f | %.1f | %.1fx | %.4f | %.4f | %.4f |\n", S, c, q / c / 1e6, e, q / e / 1e6,
                e / c, rmse_on_object(csm, converged, g), rmse_on_object(traced, converged, g),
                rmse_on_object(csm, traced, g));
  }
}

// nearest, pcf and roulette at equal samples (interleaved, median of 3), RMSE against the
// converged Embree render; progressive passes of 16 samples; the glossy BRDF (albedo 0.3,
// specular 0.5, n = 50) against its own converged render.
TEST(CoherentRender, FiltersPassesGlossy) {
  const std::unique_ptr<Measured> m = measured();
  if (!m) GTEST_SKIP() << "set SF_CSM_FILE to a .csm file";
  const io::CoherentFile& file = m->file;
  const RayTracer& tracer = *m->tracer;
  const coherent::StackLayout& l = file.stack.layout;
  const int size = m->size;
  const EnvMap& env = m->env;
  for (const bool glossy : {false, true}) {
    const GBuffer g =
        m->gbuffer(glossy ? std::array<float, 3>{0.3f, 0.3f, 0.3f} : std::array<float, 3>{0.8f, 0.8f, 0.8f});
    RenderSettings s;
    if (glossy) {
      s.specular = {0.5f, 0.5f, 0.5f};
      s.shininess = 50.0f;
    }
    s.samples = 1024;
    s.seed = 12345;
    const HostImage converged = render_traced(tracer, g, env, s);
    render_coherent(runtime(), file.stack, g, env, s);  // builds the program once, outside the timings
    std::printf("\n%s BRDF, %dx%d, %zu pixels on the object, stack %dx%d views M=%d\n", glossy ? "glossy" : "diffuse",
                size, size, g.hits, l.views_theta, l.views_phi, l.resolution);
    std::printf(
        "| samples | nearest s | pcf s | roulette s | roulette / nearest time | RMSE nearest | RMSE pcf | RMSE "
        "roulette | RMSE Embree (same samples) |\n|---|---|---|---|---|---|---|---|---|\n");
    s.seed = 1;
    for (int S : {16, 64, 256}) {
      s.samples = S;
      std::vector<double> t[3];
      HostImage img[3];
      for (int run = 0; run < 3; ++run)
        for (int f = 0; f < 3; ++f) {
          s.filter = VisibilityFilter(f);
          RenderStats k;
          img[f] = render_coherent(runtime(), file.stack, g, env, s, &k);
          t[f].push_back(k.seconds);
        }
      s.filter = VisibilityFilter::Nearest;
      const HostImage traced = render_traced(tracer, g, env, s);
      std::printf("| %d | %.3f | %.3f | %.3f | %.2fx | %.4f | %.4f | %.4f | %.4f |\n", S, median(t[0]), median(t[1]),
                  median(t[2]), median(t[2]) / median(t[0]), rmse_on_object(img[0], converged, g),
                  rmse_on_object(img[1], converged, g), rmse_on_object(img[2], converged, g),
                  rmse_on_object(traced, converged, g));
    }
    std::printf("\n| passes of 16 samples (roulette) | s | RMSE | RMSE Embree (same samples) |\n|---|---|---|---|\n");
    s.samples = 16;
    s.filter = VisibilityFilter::Roulette;
    for (int passes : {1, 4, 16, 64}) {
      s.passes = passes;
      RenderStats k;
      const HostImage img = render_coherent(runtime(), file.stack, g, env, s, &k);
      const HostImage traced = render_traced(tracer, g, env, s);
      std::printf("| %d | %.3f | %.4f | %.4f |\n", passes, k.seconds, rmse_on_object(img, converged, g),
                  rmse_on_object(traced, converged, g));
    }
  }
}

}  // namespace
}  // namespace sf::test

// Direct lighting with coherent shadow maps (docs/coherent_render.md): the
// environment map's sampling distribution, the white furnace, the coherent maps render against the
// ray-traced render of the same samples, convergence, and the command's refusals.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "cli_runner.hpp"
#include "coherent_file.hpp"
#include "coherent_reference.hpp"
#include "coherent_render.hpp"
#include "coherent_scene.hpp"
#include "coherent_stack.hpp"
#include "envmap.hpp"
#include "image_io.hpp"
#include "ray_tracer.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/coherent.hpp"

namespace sf::test {
namespace {

using namespace sf::scene;
namespace co = sf::coherent;
constexpr double kPi = 3.14159265358979323846;

// Two disjoint spheres, a small one floating over a big one: self-shadowing of the object that
// the coherent maps must resolve (a single sphere only shadows itself below its tangent planes).
struct Ball {
  Vec3 c;
  double r;
};
const std::vector<Ball> kBalls = {{{0.0, 0.0, 0.0}, 0.6}, {{0.55, 0.65, 0.3}, 0.25}};
constexpr double kBound = 1.2;  // bounding sphere at the origin: holds both balls

SceneGeometry balls_geometry() {
  SceneGeometry g;
  for (size_t i = 0; i < kBalls.size(); ++i) add_sphere(g, "ball" + std::to_string(i), kBalls[i].c, kBalls[i].r);
  return g;
}

// The dual-depth stack of the balls in closed form: along each texel's ray the sorted entry and
// exit distances of every ball; z1 the first, z2 the second (the far plane of the bounding
// sphere where there is none).
co::CompressedStack balls_stack(const std::vector<Ball>& balls, int views_side, int resolution) {
  co::DualDepthStack s;
  s.layout.views_theta = s.layout.views_phi = views_side;
  s.layout.resolution = resolution;
  s.layout.radius = kBound;
  const size_t texels = s.layout.texels();
  s.z1.assign(size_t(s.layout.views()) * texels, co::kNoSurface);
  s.z2 = s.z1;
  const std::vector<uint32_t> seq = co::enumerate_views(s.layout);
  const double R = kBound;
  auto quant = [&](double t) {
    return uint16_t(std::clamp(std::nearbyint(t / (2 * R) * co::kDepthMax), 0.0, 65534.0));
  };
  for (size_t i = 0; i < seq.size(); ++i) {
    const co::ViewFrame f = co::view_frame(s.layout, seq[i]);
    const Vec3 dir{f.dir[0], f.dir[1], f.dir[2]}, right{f.right[0], f.right[1], f.right[2]},
        up{f.up[0], f.up[1], f.up[2]};
    for (int y = 0; y < resolution; ++y)
      for (int x = 0; x < resolution; ++x) {
        const double u = (x + 0.5) / resolution * 2 - 1, v = (y + 0.5) / resolution * 2 - 1;
        const Vec3 o = R * dir + (u * R) * right + (v * R) * up, d = -dir;
        std::vector<double> ts;
        for (const Ball& b : balls) {
          const Vec3 oc = o - b.c;
          const double bb = dot(oc, d), cc = dot(oc, oc) - b.r * b.r, disc = bb * bb - cc;
          if (disc <= 0) continue;
          ts.push_back(-bb - std::sqrt(disc));
          ts.push_back(-bb + std::sqrt(disc));
        }
        std::sort(ts.begin(), ts.end());
        if (ts.empty()) continue;
        const size_t at = i * texels + size_t(y) * resolution + x;
        const uint16_t z1 = quant(ts[0]);
        const uint16_t z2 = ts.size() > 1 ? quant(ts[1]) : uint16_t(co::kDepthMax);
        s.z1[at] = z1;
        s.z2[at] = std::max<uint16_t>(z2, uint16_t(z1 + 1));
      }
  }
  return ref::coherent::compress(s);
}

// Built once for the file: 32 x 32 views of 64 x 64 texels.
const co::CompressedStack& stack() {
  static const co::CompressedStack c = balls_stack(kBalls, 32, 64);
  return c;
}
// The big ball alone (the white furnace's convex object), in the same bounding sphere.
const co::CompressedStack& ball_stack() {
  static const co::CompressedStack c = balls_stack({kBalls[0]}, 32, 64);
  return c;
}

// A 1 x 1 rectangle above and beside the balls, outside their bounding sphere: the area light of
// the balls' renders.
const AreaLight kBallsLight{{-1.5, 2.0, -0.5}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {3.0, 3.0, 3.0}};

// Framing the balls rather than the bounding sphere: more pixels on the object.
PerspectiveCamera test_camera(int size) { return framing_camera({0.1, 0.15, 0.0}, 0.8, size, size, 40.0); }

// A sky with a low sun from the side of the small ball, so its shadow falls on the big one.
const EnvMap& sky_env() {
  static const EnvMap e = [] {
    SkyOptions o;
    o.width = 64;
    o.height = 32;
    o.sun_elevation = 55.0;
    o.sun_azimuth = 35.0;
    o.sun_radius = 6.0;
    o.sun_radiance = 60.0;
    return envmap_from_image(synthetic_sky(o), "sky");
  }();
  return e;
}

// Pixels on the object (G-buffer w = 1) whose three channels in `a` are finite, >= 0, and equal
// to `b`'s within 1e-4 relative (1e-4 absolute below 1): the renders of the same samples agree.
size_t pixels_equal(const HostImage& a, const HostImage& b, const GBuffer& g) {
  size_t equal = 0;
  for (size_t i = 0; i < g.pixels(); ++i) {
    if (g.position[4 * i + 3] == 0.0f) continue;
    bool same = true;
    for (int c = 0; c < 3; ++c) {
      const float x = a.data[3 * i + c], y = b.data[3 * i + c];
      EXPECT_TRUE(std::isfinite(x) && x >= 0.0f) << "pixel " << i;
      same &= std::fabs(x - y) <= 1e-4f * std::max(1.0f, std::fabs(y));
    }
    equal += same;
  }
  return equal;
}

// The mean of `a` over the object's pixels and the three channels.
double mean_on_object(const HostImage& a, const GBuffer& g) {
  double sum = 0.0;
  for (size_t i = 0; i < g.pixels(); ++i)
    if (g.position[4 * i + 3] != 0.0f)
      for (int c = 0; c < 3; ++c) sum += a.data[3 * i + c];
  return sum / (3.0 * double(g.hits));
}

// --- the environment map ---------------------------------------------------------------------

TEST(CoherentRender, EnvSamplingFollowsLuminance) {
  const int W = 16, H = 8;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> val(0.0f, 2.0f);
  std::vector<float> rgb(size_t(W) * H * 3);
  for (float& v : rgb) v = val(rng);
  for (int c = 0; c < 3; ++c) rgb[(3 * W + 5) * 3 + c] = 0.0f;   // a black texel is never drawn
  for (int c = 0; c < 3; ++c) rgb[(6 * W + 2) * 3 + c] = 20.0f;  // a bright one often
  const EnvMap env = make_envmap(W, H, rgb, "test");
  // Expected probabilities in double: luminance times the texel's exact solid angle.
  std::vector<double> expected(size_t(W) * H);
  double total = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double omega = (std::cos(kPi * y / H) - std::cos(kPi * (y + 1) / H)) * 2 * kPi / W;
      expected[y * W + x] = double(env.luminance(x, y)) * omega;
      total += expected[y * W + x];
    }
  double pdf_integral = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      expected[y * W + x] /= total;
      const double omega = (std::cos(kPi * y / H) - std::cos(kPi * (y + 1) / H)) * 2 * kPi / W;
      pdf_integral += envmap_pdf(env, x, y) * omega;
      EXPECT_NEAR(envmap_pdf(env, x, y) * omega, expected[y * W + x], 1e-5) << x << "," << y;
    }
  EXPECT_NEAR(pdf_integral, 1.0, 1e-3);
  // Chi-square of 200k draws against the expected counts (127 degrees of freedom: mean 127,
  // sd 16; the bound is mean + 5 sd).
  const int N = 200000;
  std::vector<int> counts(expected.size(), 0);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  int wrong_texel = 0;
  for (int n = 0; n < N; ++n) {
    const EnvSample s = sample_envmap(env, std::min(u01(rng), 0x1.fffffep-1f), std::min(u01(rng), 0x1.fffffep-1f));
    ++counts[s.y * W + s.x];
    int tx, ty;
    envmap_texel_of(env, s.dir, &tx, &ty);
    wrong_texel += (tx != s.x || ty != s.y);
    ASSERT_GT(s.pdf, 0.0f);
    ASSERT_NEAR(std::hypot(s.dir[0], s.dir[1], s.dir[2]), 1.0, 1e-5);
  }
  EXPECT_EQ(counts[3 * W + 5], 0);
  double chi2 = 0.0;
  int bins = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    const double e = expected[i] * N;
    if (e < 5.0) continue;
    chi2 += (counts[i] - e) * (counts[i] - e) / e;
    ++bins;
  }
  EXPECT_GT(bins, 120);
  EXPECT_LT(chi2, (bins - 1) + 5.0 * std::sqrt(2.0 * (bins - 1)));
  // Directions land in the texel they were drawn from (float rounding on a border aside).
  EXPECT_LT(wrong_texel, N / 1000);
}

TEST(CoherentRender, EnvMapRefusesBadTexels) {
  for (float bad : {std::nanf(""), INFINITY, -1.0f, 1e21f}) {
    std::vector<float> rgb(4 * 2 * 3, 1.0f);
    rgb[7] = bad;
    EXPECT_THROW(make_envmap(4, 2, rgb, "bad"), InputError) << bad;
  }
  EXPECT_THROW(make_envmap(0, 2, {}, "empty"), InputError);
  // An all-black map is valid: lit by area lights alone.
  EXPECT_FALSE(make_envmap(4, 2, std::vector<float>(24, 0.0f), "black").sampled);
  const std::string dir = temp_dir("coherent_render_env");
  EXPECT_THROW(load_envmap(dir + "/missing.exr"), InputError);
  std::ofstream(dir + "/junk.exr") << "not an image";
  EXPECT_THROW(load_envmap(dir + "/junk.exr"), InputError);
  // A valid map, then the same bytes cut in half.
  io::write_image(dir + "/sky.exr", synthetic_sky(SkyOptions{}));
  EXPECT_NO_THROW(load_envmap(dir + "/sky.exr"));
  const auto size = std::filesystem::file_size(dir + "/sky.exr");
  std::filesystem::resize_file(dir + "/sky.exr", size / 2);
  EXPECT_THROW(load_envmap(dir + "/sky.exr"), InputError);
  HostImage nan_map(8, 4, 3, 1.0f);
  nan_map.at(3, 2, 1) = std::nanf("");
  io::write_image(dir + "/nan.exr", nan_map);
  try {
    load_envmap(dir + "/nan.exr");
    ADD_FAILURE() << "a NaN texel was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("x=3, y=2"), std::string::npos) << e.what();
  }
}

TEST(CoherentRender, SyntheticSkyIsDeterministicAndBundled) {
  const HostImage a = synthetic_sky(SkyOptions{}), b = synthetic_sky(SkyOptions{});
  EXPECT_EQ(a.data, b.data);
  // The brightest texel is the sun's: elevation 40, azimuth 60 degrees.
  const auto it = std::max_element(a.data.begin(), a.data.end());
  const size_t t = size_t(it - a.data.begin()) / 3;
  const double theta = (double(t / a.width) + 0.5) / a.height * 180.0,
               phi = (double(t % a.width) + 0.5) / a.width * 360.0;
  EXPECT_NEAR(theta, 50.0, 3.0);
  EXPECT_NEAR(phi, 60.0, 3.0);
  const EnvMap bundled = load_envmap(data_path("envmaps/sky.exr"));
  EXPECT_LE(bundled.width, 256);
  EXPECT_LE(bundled.height, 128);
  EXPECT_TRUE(bundled.sampled);
}

// --- renders ---------------------------------------------------------------------------------

// Uniform env = 1, albedo 1, a convex object: every point sees radiance 1. Per sample the
// estimate is 4 cos (or 0 below the horizon): sd 1.29 a sample, at 64 stratified samples at
// most 0.16 a pixel. Bounds: the mean over the object within 0.01 of 1, ray-traced and with the
// coherent maps (whose grazing samples snap to a view up to half a cell away and may read as blocked: a
// bias, measured 0.0005 for 32 x 32 views), every ray-traced pixel within 0.5.
TEST(CoherentRender, WhiteFurnace) {
  SceneGeometry ball;
  add_sphere(ball, "ball", {0, 0, 0}, 0.6);
  const RayTracer tracer(ball);
  const GBuffer g = render_gbuffer(tracer, test_camera(48), kBound, {1.0f, 1.0f, 1.0f});
  const EnvMap env = uniform_envmap(32, 16, 1.0f);
  RenderSettings s;
  s.samples = 64;
  const HostImage traced = render_traced(tracer, g, env, s);
  const HostImage maps = render_coherent(runtime(), ball_stack(), g, env, s);
  double mean_t = 0.0, mean_c = 0.0, worst = 0.0;
  for (size_t i = 0; i < g.pixels(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(maps.data[3 * i + c]));
      if (g.position[4 * i + 3] == 0.0f) {  // background: the environment itself
        EXPECT_EQ(traced.data[3 * i + c], 1.0f);
        EXPECT_EQ(maps.data[3 * i + c], 1.0f);
      }
    }
    if (g.position[4 * i + 3] == 0.0f) continue;
    mean_t += traced.data[3 * i];
    mean_c += maps.data[3 * i];
    worst = std::max(worst, std::fabs(traced.data[3 * i] - 1.0));
  }
  ASSERT_GT(g.hits, 200u);
  mean_t /= double(g.hits);
  mean_c /= double(g.hits);
  std::printf("furnace: mean traced %.4f, coherent %.4f, worst traced pixel %.3f off\n", mean_t, mean_c, worst);
  EXPECT_NEAR(mean_t, 1.0, 0.01);
  EXPECT_LT(worst, 0.5);
  EXPECT_NEAR(mean_c, 1.0, 0.01);
}

// The coherent-map render against the ray-traced render of the same samples: they differ where a sample's
// visibility does, at the coherent maps' discretisation (views 5.6 x 11 degrees, 64 x 64 texels). And the
// kernel against its host twin with the scalar coherent-map lookup: the same samples, the same answers.
TEST(CoherentRender, CoherentMatchesTracedOnSameSamples) {
  const SceneGeometry geometry = balls_geometry();
  const RayTracer tracer(geometry);
  const GBuffer g = render_gbuffer(tracer, test_camera(64), kBound, {0.8f, 0.8f, 0.8f});
  RenderSettings s;
  s.samples = 16;
  s.lights.push_back(kBallsLight);
  validate_area_light(s.lights[0], {0, 0, 0}, kBound);
  const HostImage maps = render_coherent(runtime(), stack(), g, sky_env(), s);
  const HostImage traced = render_traced(tracer, g, sky_env(), s);
  const std::vector<uint32_t> pos = co::sequence_positions(stack().layout);
  const HostImage twin = render_host(g, sky_env(), s, [&](const VisibilityQuery& q) {
    return float(ref::coherent::visibility(stack(), pos, {q.p[0], q.p[1], q.p[2]}, {q.d[0], q.d[1], q.d[2]}));
  });
  const size_t exact_traced = pixels_equal(maps, traced, g), exact_twin = pixels_equal(maps, twin, g);
  const double mean = mean_on_object(traced, g);
  const double rmse = rmse_on_object(maps, traced, g);
  std::printf("hits %zu, equal to traced %zu, to the host twin %zu; rmse %.4f (mean %.3f)\n", g.hits, exact_traced,
              exact_twin, rmse, mean);
  EXPECT_GE(double(exact_twin), 0.99 * double(g.hits));
  // The filtered lookup: fractional visibility, finite, closer to the ray-traced render.
  s.filter = VisibilityFilter::Pcf;
  const HostImage pcf = render_coherent(runtime(), stack(), g, sky_env(), s);
  for (float v : pcf.data) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
  const double rmse_pcf = rmse_on_object(pcf, traced, g);
  std::printf("pcf: rmse against traced %.4f\n", rmse_pcf);
  EXPECT_LT(rmse_pcf, 0.1 * mean);
  EXPECT_GE(double(exact_traced), 0.7 * double(g.hits));
  EXPECT_LT(rmse, 0.1 * mean);
}

// Error against a converged render (1024 samples, another seed) as samples grow: 4 -> 64 samples
// is 16 times the samples, 4 times less noise (more where stratification helps); the ray-traced
// render must gain at least 3x, the coherent maps' error is noise plus its discretisation bias.
TEST(CoherentRender, ConvergesAsSamplesGrow) {
  const SceneGeometry geometry = balls_geometry();
  const RayTracer tracer(geometry);
  const GBuffer g = render_gbuffer(tracer, test_camera(32), kBound, {0.8f, 0.8f, 0.8f});
  RenderSettings s;
  s.lights.push_back(kBallsLight);
  s.samples = 1024;
  s.seed = 99;
  const HostImage converged = render_traced(tracer, g, sky_env(), s);
  s.seed = 1;
  double traced_err[2], csm_err[2];
  const int counts[2] = {4, 64};
  for (int k = 0; k < 2; ++k) {
    s.samples = counts[k];
    traced_err[k] = rmse_on_object(render_traced(tracer, g, sky_env(), s), converged, g);
    csm_err[k] = rmse_on_object(render_coherent(runtime(), stack(), g, sky_env(), s), converged, g);
  }
  std::printf("rmse traced %.4f -> %.4f (x%.2f), csm %.4f -> %.4f (x%.2f)\n", traced_err[0], traced_err[1],
              traced_err[0] / traced_err[1], csm_err[0], csm_err[1], csm_err[0] / csm_err[1]);
  EXPECT_GT(traced_err[0] / traced_err[1], 3.0);
  EXPECT_GT(csm_err[0] / csm_err[1], 2.0);
}

// --- filters, glossy reflection, progressive passes ------------------------------------------

// Russian roulette picks one of generalized PCF's 16 tests with its weight as probability: over
// many draws its mean is PCF's value. 300 point-direction pairs around the balls' shadow, 2048
// draws each: every mean within 5 standard errors (+ 1e-9) of visibility_filtered, and each draw 0 or 1.
TEST(CoherentRender, RouletteMeanIsGeneralizedPcf) {
  const std::vector<uint32_t> pos = co::sequence_positions(stack().layout);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  int fractional = 0;
  for (int k = 0; k < 300; ++k) {
    // A point on the big ball facing the small one, a direction toward the small one's region.
    const double a = angle(rng), b = 0.25 * angle(rng);
    const Vec3 n{std::cos(a) * std::sin(b), std::cos(b), std::sin(a) * std::sin(b)};
    const Vec3 p = kBalls[0].c + (kBalls[0].r + 1e-3) * n;
    const Vec3 d = (kBalls[1].c - p) + 0.3 * Vec3{std::cos(3 * a), std::sin(5 * b), std::sin(a + b)};
    const double pcf = ref::coherent::visibility_filtered(stack(), pos, p, d);
    fractional += pcf > 0.0 && pcf < 1.0;
    double sum = 0.0;
    constexpr int kDraws = 2048;
    for (int t = 0; t < kDraws; ++t) {
      const double v = ref::coherent::visibility_roulette(stack(), pos, p, d, {u01(rng), u01(rng), u01(rng), u01(rng)});
      ASSERT_TRUE(v == 0.0 || v == 1.0);
      sum += v;
    }
    const double mean = sum / kDraws, se = std::sqrt(pcf * (1.0 - pcf) / kDraws);
    EXPECT_NEAR(mean, pcf, 5.0 * se + 1e-9) << "pair " << k;
  }
  std::printf("roulette: %d of 300 pairs with fractional PCF\n", fractional);
  EXPECT_GE(fractional, 30);  // the pairs exercise the filter, not only lit or blocked texels
}

// The kernel's roulette and glossy paths against the host twin with the scalar lookups (the same
// random numbers): equal on >= 99% of pixels (relative 1e-4, measured 100%); roulette's render
// approaches PCF's on the same samples as S grows (the roulette's own noise: 4 -> 64 samples at
// least 3x less; measured 4.4x, the 1/sqrt(S) of independent draws).
TEST(CoherentRender, RouletteAndGlossyMatchTheirHostTwin) {
  const SceneGeometry geometry = balls_geometry();
  const RayTracer tracer(geometry);
  const GBuffer g = render_gbuffer(tracer, test_camera(48), kBound, {0.5f, 0.5f, 0.5f});
  const std::vector<uint32_t> pos = co::sequence_positions(stack().layout);
  RenderSettings s;
  s.samples = 16;
  s.lights.push_back(kBallsLight);
  auto agreement = [&](const HostImage& a, const HostImage& b) {
    return double(pixels_equal(a, b, g)) / double(g.hits);
  };
  const Visibility nearest = [&](const VisibilityQuery& q) {
    return float(ref::coherent::visibility(stack(), pos, {q.p[0], q.p[1], q.p[2]}, {q.d[0], q.d[1], q.d[2]}));
  };
  const Visibility roulette = [&](const VisibilityQuery& q) {
    return float(
        ref::coherent::visibility_roulette(stack(), pos, {q.p[0], q.p[1], q.p[2]}, {q.d[0], q.d[1], q.d[2]}, q.r));
  };
  s.filter = VisibilityFilter::Roulette;
  const double roulette_equal =
      agreement(render_coherent(runtime(), stack(), g, sky_env(), s), render_host(g, sky_env(), s, roulette));
  s.filter = VisibilityFilter::Nearest;
  s.specular = {0.4f, 0.4f, 0.4f};
  s.shininess = 40.0f;
  const double glossy_equal =
      agreement(render_coherent(runtime(), stack(), g, sky_env(), s), render_host(g, sky_env(), s, nearest));
  s.filter = VisibilityFilter::Roulette;
  const double both_equal =
      agreement(render_coherent(runtime(), stack(), g, sky_env(), s), render_host(g, sky_env(), s, roulette));
  std::printf("equal to the host twin: roulette %.4f, glossy %.4f, glossy roulette %.4f\n", roulette_equal,
              glossy_equal, both_equal);
  EXPECT_GE(roulette_equal, 0.99);
  EXPECT_GE(glossy_equal, 0.99);
  EXPECT_GE(both_equal, 0.99);

  s.specular = {0.0f, 0.0f, 0.0f};
  double gap[2];
  const int counts[2] = {4, 64};
  for (int k = 0; k < 2; ++k) {
    s.samples = counts[k];
    s.filter = VisibilityFilter::Pcf;
    const HostImage pcf = render_coherent(runtime(), stack(), g, sky_env(), s);
    s.filter = VisibilityFilter::Roulette;
    gap[k] = rmse_on_object(render_coherent(runtime(), stack(), g, sky_env(), s), pcf, g);
  }
  std::printf("roulette vs pcf on the same samples: rmse %.4f (4 samples) -> %.4f (64), x%.2f\n", gap[0], gap[1],
              gap[0] / gap[1]);
  EXPECT_GT(gap[0] / gap[1], 3.0);
}

// The glossy estimator is unbiased: a lone sphere (convex: every direction above the horizon is
// free) under the sky, albedo 0.3 and specular 0.6 with n = 20, rendered with Embree rays at 4096
// samples, against a quadrature of the same integral over the map's texels (8 x 8 points a
// texel, the map's nearest-texel radiance): the object's mean within 1% (measured 0.02%) and the
// RMSE over pixels within 3.5% of the mean (measured 2.3%, 4.1% at 1024 samples: noise).
TEST(CoherentRender, GlossyMisMatchesQuadrature) {
  SceneGeometry ball;
  add_sphere(ball, "ball", {0, 0, 0}, 0.6);
  const RayTracer tracer(ball);
  const GBuffer g = render_gbuffer(tracer, test_camera(20), kBound, {0.3f, 0.3f, 0.3f});
  const EnvMap& env = sky_env();
  RenderSettings s;
  s.samples = 4096;
  s.specular = {0.6f, 0.6f, 0.6f};
  s.shininess = 20.0f;
  const HostImage traced = render_traced(tracer, g, env, s);
  // Quadrature directions: 8 x 8 points a texel, uniform in cos theta and phi, each with its
  // solid angle; the texel's radiance.
  struct Dir {
    Vec3 w;
    double weight;
    std::array<float, 3> L;
  };
  std::vector<Dir> dirs;
  constexpr int kSub = 8;
  for (int y = 0; y < env.height; ++y)
    for (int x = 0; x < env.width; ++x)
      for (int b = 0; b < kSub; ++b)
        for (int a = 0; a < kSub; ++a) {
          const double c0 = std::cos(kPi * y / env.height), c1 = std::cos(kPi * (y + 1) / env.height);
          const double ct = c0 + (c1 - c0) * (b + 0.5) / kSub, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
          const double phi = 2.0 * kPi * (x + (a + 0.5) / kSub) / env.width;
          const double sa = (c0 - c1) * 2.0 * kPi / env.width / (kSub * kSub);
          dirs.push_back({{st * std::cos(phi), ct, st * std::sin(phi)}, sa, env.texel(x, y)});
        }
  double sum_err2 = 0.0, mean_r = 0.0, mean_q = 0.0;
  for (size_t i = 0; i < g.pixels(); ++i) {
    if (g.position[4 * i + 3] == 0.0f) continue;
    const Vec3 p{g.position[4 * i], g.position[4 * i + 1], g.position[4 * i + 2]};
    const Vec3 n{g.normal[4 * i], g.normal[4 * i + 1], g.normal[4 * i + 2]};
    const Vec3 wo = normalize(Vec3{g.eye[0], g.eye[1], g.eye[2]} - p);
    const Vec3 R = 2.0 * dot(n, wo) * n - wo;
    double q = 0.0;  // the green channel: the sky's sun and gradient both reach it
    for (const Dir& d : dirs) {
      const double c = dot(n, d.w);
      if (c <= 0.0) continue;
      const double pi_f = 0.3 + 0.6 * (20.0 + 2.0) / 2.0 * std::pow(std::max(0.0, dot(R, d.w)), 20.0);
      q += d.L[1] * pi_f / kPi * c * d.weight;
    }
    const double r = traced.data[3 * i + 1];
    sum_err2 += (r - q) * (r - q);
    mean_r += r;
    mean_q += q;
  }
  ASSERT_GT(g.hits, 100u);
  mean_r /= double(g.hits);
  mean_q /= double(g.hits);
  const double rmse = std::sqrt(sum_err2 / double(g.hits));
  std::printf("glossy: mean render %.4f, quadrature %.4f (%.2f%%), rmse %.4f (%.2f%% of the mean)\n", mean_r, mean_q,
              100.0 * (mean_r / mean_q - 1.0), rmse, 100.0 * rmse / mean_q);
  EXPECT_NEAR(mean_r / mean_q, 1.0, 0.01);
  EXPECT_LT(rmse, 0.035 * mean_q);
}

// Progressive passes: P passes equal the running mean of P single-pass renders with the passes'
// seeds, bit for bit, on the device and on the host; the error against a converged render falls
// as passes accumulate (1 -> 16 passes: at least 2.5x); a budget shorter than any pass runs one.
TEST(CoherentRender, ProgressivePassesAverage) {
  const SceneGeometry geometry = balls_geometry();
  const RayTracer tracer(geometry);
  const GBuffer g = render_gbuffer(tracer, test_camera(32), kBound, {0.8f, 0.8f, 0.8f});
  RenderSettings s;
  s.samples = 4;
  s.lights.push_back(kBallsLight);
  s.passes = 3;
  RenderStats stats;
  const HostImage three = render_coherent(runtime(), stack(), g, sky_env(), s, &stats);
  EXPECT_EQ(stats.passes, 3);
  const HostImage three_host = render_traced(tracer, g, sky_env(), s);
  HostImage manual, manual_host;
  for (int m = 0; m < 3; ++m) {
    RenderSettings one = s;
    one.passes = 1;
    one.seed = pass_seed(s.seed, m);
    const HostImage a = render_coherent(runtime(), stack(), g, sky_env(), one);
    const HostImage b = render_traced(tracer, g, sky_env(), one);
    if (m == 0) {
      manual = a;
      manual_host = b;
      continue;
    }
    for (size_t k = 0; k < a.data.size(); ++k) {
      manual.data[k] = manual.data[k] + (a.data[k] - manual.data[k]) / float(m + 1);
      manual_host.data[k] = manual_host.data[k] + (b.data[k] - manual_host.data[k]) / float(m + 1);
    }
  }
  EXPECT_EQ(three.data, manual.data);
  EXPECT_EQ(three_host.data, manual_host.data);
  EXPECT_NE(pass_seed(s.seed, 1), s.seed);

  RenderSettings c = s;
  c.samples = 512;
  c.passes = 1;
  c.seed = 99;
  const HostImage converged = render_traced(tracer, g, sky_env(), c);
  s.passes = 1;
  const double one_pass = rmse_on_object(render_traced(tracer, g, sky_env(), s), converged, g);
  s.passes = 16;
  const double sixteen = rmse_on_object(render_traced(tracer, g, sky_env(), s), converged, g);
  std::printf("progressive: rmse 1 pass %.4f, 16 passes %.4f (x%.2f)\n", one_pass, sixteen, one_pass / sixteen);
  EXPECT_GT(one_pass / sixteen, 2.5);

  s.passes = kMaxPasses;
  s.time_budget = 1e-9;
  render_coherent(runtime(), stack(), g, sky_env(), s, &stats);
  EXPECT_EQ(stats.passes, 1);
}

// --- several objects, moving (seed sec. 4.6) -------------------------------------------------

// The built-in box (2 x 1 x 1.5) with maps of 32 x 32 views of 64 x 64 texels, and a ball of
// radius 0.3 with its own maps: two objects of a scene.
struct TwoObjects {
  SceneGeometry box = load_coherent_object("box");
  co::CompressedStack box_maps, ball_maps;
  SceneGeometry ball;
  TwoObjects() {
    co::StackLayout layout;
    layout.views_theta = layout.views_phi = 32;
    layout.resolution = 64;
    fit_bounding_sphere(box, layout);
    box_maps = ref::coherent::compress(render_stack(box, layout, 0));
    add_sphere(ball, "ball", {0.0, 0.0, 0.0}, 0.3);
    fit_bounding_sphere(ball, layout);
    ball_maps = ref::coherent::compress(render_stack(ball, layout, 0));
  }
  // The box turned 35 degrees about a tilted axis; the ball above its corner, moving along +x
  // 0.15 a frame; a receiver-only ground plane under both.
  std::vector<SceneObject> objects() const {
    std::vector<SceneObject> o(2);
    o[0].stack = &box_maps;
    o[0].geometry = box;
    o[0].placement = rotation_about({0.2, 1.0, 0.3}, 35.0, o[0].center(), "test");
    o[1].stack = &ball_maps;
    o[1].geometry = ball;
    o[1].placement = translation_by({-0.6, 1.3, 0.2});
    o[1].move = {0.15, 0.0, 0.0};
    o[1].spin_degrees = 20.0;
    return o;
  }
};
const TwoObjects& two_objects() {
  static const TwoObjects t;
  return t;
}

// Two objects shadowing each other and a ground plane, frames 0 and 3: the coherent render
// against Embree rays on the placed meshes (same samples), and against its host twin (scalar
// lookups through the same world-to-object floats); and the same render with the box left
// unturned in its maps while its mesh turns (a wrong D' = D T^-1) is measurably worse.
TEST(CoherentRender, MovingObjectsMatchEmbree) {
  const TwoObjects& t = two_objects();
  std::vector<SceneObject> objects = t.objects();
  std::vector<GroundPlane> planes(1);
  planes[0].height = -1.0;
  planes[0].half_size = 4.0;
  RenderSettings s;
  s.samples = 16;
  s.lights.push_back({{-2.0, 3.0, -1.0}, {1.5, 0.0, 0.0}, {0.0, 0.0, 1.5}, {4.0, 4.0, 4.0}});
  for (const int frame : {0, 3}) {
    std::vector<std::array<float, 3>> albedo;
    const SceneGeometry world = world_geometry(objects, planes, frame, &albedo);
    ASSERT_EQ(albedo.size(), world.meshes.size() + world.spheres.size());
    const RayTracer tracer(world);
    const GBuffer g = render_gbuffer(tracer, framing_camera({0.0, -0.2, 0.0}, 1.8, 56, 56, 40.0), 2.0, albedo);
    const std::vector<PlacedStack> placed = placed_stacks(objects, frame);
    const HostImage maps = render_coherent(runtime(), placed, g, sky_env(), s);
    const HostImage traced = render_traced(tracer, g, sky_env(), s);
    std::vector<std::vector<uint32_t>> pos;
    std::vector<ObjectRows> rows;
    for (const PlacedStack& p : placed) {
      pos.push_back(co::sequence_positions(p.stack->layout));
      rows.push_back(object_rows(p.transform));
    }
    const HostImage twin = render_host(g, sky_env(), s, [&](const VisibilityQuery& q) {
      float v = 1.0f;
      for (size_t o = 0; o < placed.size() && v > 0.0f; ++o) {
        const auto po = to_object_point(rows[o], q.p), dobj = to_object_direction(rows[o], q.d);
        v *= float(
            ref::coherent::visibility(*placed[o].stack, pos[o], {po[0], po[1], po[2]}, {dobj[0], dobj[1], dobj[2]}));
      }
      return v;
    });
    const size_t equal_traced = pixels_equal(maps, traced, g), equal_twin = pixels_equal(maps, twin, g);
    const double mean = mean_on_object(traced, g);
    const double rmse = rmse_on_object(maps, traced, g);
    // The box's maps used as if it had not turned: the shadows of the turned mesh are missed.
    std::vector<PlacedStack> wrong = placed;
    wrong[0].transform = RigidTransform{};
    const double rmse_wrong = rmse_on_object(render_coherent(runtime(), wrong, g, sky_env(), s), traced, g);
    std::printf(
        "frame %d: %zu pixels on surfaces, equal to Embree %zu, to the twin %zu; rmse %.4f (mean %.3f), "
        "unturned maps %.4f\n",
        frame, g.hits, equal_traced, equal_twin, rmse, mean, rmse_wrong);
    ASSERT_GT(g.hits, 1500u);
    EXPECT_GE(double(equal_twin), 0.99 * double(g.hits));
    // Measured: 53% and 57% of the pixels equal (all 32 samples' answers the same; the ground's
    // penumbrae lie far from the objects, where a view's 5.6 x 11 degree snap moves a shadow
    // most), RMSE 4.1% of the mean, the unturned maps 2.7x worse.
    EXPECT_GE(double(equal_traced), 0.45 * double(g.hits));
    EXPECT_LT(rmse, 0.06 * mean);
    EXPECT_GT(rmse_wrong, 2.0 * rmse);
  }
}

// A fixed local light (seed sec. 4.2) inside the bounding sphere of two boxes, the small one
// floating over the big one, in a black environment: the render with the light's depth cube maps
// (8 x 8 sampling points, M = 128) against the host twin with the scalar cube-map lookup (>= 99%
// of pixels equal; measured 100%), against Embree rays toward the samples' sampling points (the
// maps' own error: RMSE < 5% of the mean, measured 3.9%) and toward the samples themselves (< 20%,
// measured 13%: the light as 64 points, which the seed's renderer is too, is most of it); the
// same render without the maps' shadows is > 5x worse (measured 10.8x).
TEST(CoherentRender, LocalLightMatchesEmbree) {
  SceneGeometry boxes;
  add_box(boxes, "big", {-1.0, -0.5, -0.75}, {1.0, 0.5, 0.75});
  add_box(boxes, "small", {-0.3, 0.7, -0.3}, {0.3, 0.8, 0.3});
  co::LocalLight light;
  light.corner = {-0.5, 1.1, -0.5};
  light.edge_a = {1.0, 0.0, 0.0};
  light.edge_b = {0.0, 0.0, 1.0};
  light.samples_a = light.samples_b = 8;
  const co::CompressedStack cube = ref::coherent::compress(render_cube_stack(boxes, light, 128, 0));
  co::StackLayout layout;
  layout.views_theta = layout.views_phi = 16;
  layout.resolution = 32;
  fit_bounding_sphere(boxes, layout);
  const co::CompressedStack distant = ref::coherent::compress(render_stack(boxes, layout, 0));
  const RayTracer tracer(boxes);
  const GBuffer g = render_gbuffer(tracer, framing_camera({0.0, 0.2, 0.0}, 1.3, 56, 56, 40.0), 1.4,
                                   std::array<float, 3>{0.8f, 0.8f, 0.8f});
  const EnvMap black = uniform_envmap(16, 8, 0.0f);
  RenderSettings s;
  s.samples = 16;
  s.local_light = RenderSettings::LocalLightSource{light, {5.0, 5.0, 5.0}};
  const HostImage csm = render_coherent(runtime(), {{&distant, RigidTransform{}}}, g, black, s, nullptr, &cube);
  const HostImage traced = render_traced(tracer, g, black, s);
  const std::vector<uint32_t> positions = co::light_positions(light);
  const HostImage twin = render_host(g, black, s, [&](const VisibilityQuery& q) {
    EXPECT_EQ(q.light, 0);  // the local light, after the (no) area lights
    const int a = std::min(int(q.u * float(light.samples_a)), light.samples_a - 1);
    const int b = std::min(int(q.v * float(light.samples_b)), light.samples_b - 1);
    return float(ref::coherent::local_visibility(cube, light, positions, uint32_t(b * light.samples_a + a),
                                                 {q.p[0], q.p[1], q.p[2]}));
  });
  const size_t equal_traced = pixels_equal(csm, traced, g), equal_twin = pixels_equal(csm, twin, g);
  const double mean = mean_on_object(traced, g);
  const double rmse = rmse_on_object(csm, traced, g);
  // The light as its sampling points: Embree rays toward the cell's sampling point instead of
  // the sample itself. The maps' own error is against this; the rest is the light's
  // discretisation into 64 points, which the seed's renderer has too.
  const HostImage snapped = render_host(g, black, s, [&](const VisibilityQuery& q) {
    const int a = std::min(int(q.u * float(light.samples_a)), light.samples_a - 1);
    const int b = std::min(int(q.v * float(light.samples_b)), light.samples_b - 1);
    const Vec3 p{q.p[0], q.p[1], q.p[2]}, to = light.sample_point(uint32_t(b * light.samples_a + a)) - p;
    return tracer.occluded({p, normalize(to)}, 0.0, length(to), kMaskOccluders) ? 0.0f : 1.0f;
  });
  const double rmse_snapped = rmse_on_object(csm, snapped, g), rmse_points = rmse_on_object(snapped, traced, g);
  // Without its cube maps the light would be unoccluded: the shadow of the small box is missed.
  const double rmse_unshadowed =
      rmse_on_object(render_host(g, black, s, [](const VisibilityQuery&) { return 1.0f; }), traced, g);
  std::printf(
      "local light: %zu pixels, equal to Embree %zu, to the twin %zu; rmse %.4f (mean %.3f): against Embree toward "
      "the sampling points %.4f, those against Embree %.4f; unshadowed %.4f\n",
      g.hits, equal_traced, equal_twin, rmse, mean, rmse_snapped, rmse_points, rmse_unshadowed);
  ASSERT_GT(g.hits, 800u);
  EXPECT_GE(double(equal_twin), 0.99 * double(g.hits));
  EXPECT_GE(double(equal_traced), 0.7 * double(g.hits));
  EXPECT_LT(rmse_snapped, 0.05 * mean);
  EXPECT_LT(rmse, 0.2 * mean);
  EXPECT_GT(rmse_unshadowed, 5.0 * rmse);
  // Maps of another grid, or a light without maps, are refused.
  RenderSettings other = s;
  other.local_light->light.samples_a = 4;
  other.local_light->light.samples_b = 4;
  EXPECT_THROW(render_coherent(runtime(), {{&distant, RigidTransform{}}}, g, black, other, nullptr, &cube), InputError);
  EXPECT_THROW(render_coherent(runtime(), {{&distant, RigidTransform{}}}, g, black, s), InputError);

  // The same rectangle as a mesh light (two triangles, 64 sampling points on them): a sample is a
  // sampling point, so the render differs from Embree's rays toward the same points by the maps'
  // discretisation alone.
  TriMesh quad;
  quad.name = "quad";
  quad.vertices = {light.corner, light.corner + light.edge_a, light.corner + light.edge_a + light.edge_b,
                   light.corner + light.edge_b};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  co::LocalLight mesh = mesh_light(quad, 64);
  EXPECT_NEAR(mesh.area, 1.0, 1e-12);
  const co::CompressedStack mesh_cube = ref::coherent::compress(render_cube_stack(boxes, mesh, 128, 0));
  RenderSettings m = s;
  m.local_light = RenderSettings::LocalLightSource{mesh, {5.0, 5.0, 5.0}};
  const HostImage mesh_csm =
      render_coherent(runtime(), {{&distant, RigidTransform{}}}, g, black, m, nullptr, &mesh_cube);
  const HostImage mesh_traced = render_traced(tracer, g, black, m);
  const std::vector<uint32_t> mesh_positions = co::light_positions(mesh);
  const HostImage mesh_twin = render_host(g, black, m, [&](const VisibilityQuery& q) {
    const int j = std::min(int(q.u * float(mesh.count())), mesh.count() - 1);
    return float(
        ref::coherent::local_visibility(mesh_cube, mesh, mesh_positions, uint32_t(j), {q.p[0], q.p[1], q.p[2]}));
  });
  const size_t mesh_equal_twin = pixels_equal(mesh_csm, mesh_twin, g);
  const double mesh_rmse = rmse_on_object(mesh_csm, mesh_traced, g);
  // The mesh light and the rectangle are one light: their Embree renders agree on average within
  // 5% (measured 2.9%: the mesh light's samples are its 64 points, the rectangle's any point;
  // each pixel's 16 samples are noisy, a light this close varies fast over its area). The maps'
  // own error: RMSE < 8% of the mean (measured 5.6%).
  const double mesh_mean = mean_on_object(mesh_traced, g);
  std::printf("mesh light: equal to the twin %zu of %zu; rmse against Embree %.4f; mean %.4f (rectangle %.4f)\n",
              mesh_equal_twin, g.hits, mesh_rmse, mesh_mean, mean);
  EXPECT_GE(double(mesh_equal_twin), 0.99 * double(g.hits));
  EXPECT_LT(mesh_rmse, 0.08 * mean);
  EXPECT_NEAR(mesh_mean / mean, 1.0, 0.05);
}

TEST(CoherentRender, RigidTransformsComposeAndInvert) {
  const RigidTransform r = rotation_about({1.0, 2.0, -0.5}, 73.0, {0.3, -0.2, 0.9}, "test");
  const RigidTransform t = r.then(translation_by({1.0, -2.0, 0.5}));
  const ObjectRows rows = object_rows(t);
  for (const Vec3 p : {Vec3{0.0, 0.0, 0.0}, Vec3{1.0, 2.0, 3.0}, Vec3{-0.7, 0.2, 0.1}}) {
    const Vec3 w = t.apply(p);
    const auto back = to_object_point(rows, {float(w.x), float(w.y), float(w.z)});
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(back[a], p[a], 2e-6);
  }
  // The pivot stays; lengths and angles stay.
  const Vec3 pivot = r.apply({0.3, -0.2, 0.9});
  EXPECT_NEAR(length(pivot - Vec3{0.3, -0.2, 0.9}), 0.0, 1e-12);
  EXPECT_NEAR(length(r.rotate({1.0, 0.0, 0.0})), 1.0, 1e-12);
  EXPECT_NEAR(dot(r.rotate({1.0, 0.0, 0.0}), r.rotate({0.0, 1.0, 0.0})), 0.0, 1e-12);
  EXPECT_THROW(rotation_about({0.0, 0.0, 0.0}, 10.0, {0.0, 0.0, 0.0}, "test"), InputError);
  EXPECT_THROW(rotation_about({0.0, 1.0, 0.0}, std::nan(""), {0.0, 0.0, 0.0}, "test"), InputError);
  // A spin per frame about the placed centre: the centre stays, frame 2 is two spins.
  SceneObject o;
  o.stack = &two_objects().ball_maps;
  o.placement = translation_by({1.0, 0.0, 0.0});
  o.spin_degrees = 30.0;
  o.move = {0.0, 0.5, 0.0};
  const Vec3 c2 = o.at_frame(2).apply(o.center());
  EXPECT_NEAR(length(c2 - (o.placement.apply(o.center()) + Vec3{0.0, 1.0, 0.0})), 0.0, 1e-12);
  const Vec3 x2 = o.at_frame(2).rotate({1.0, 0.0, 0.0});
  EXPECT_NEAR(x2.x, std::cos(60.0 * kPi / 180.0), 1e-12);
}

TEST(CoherentRender, AreaLightsInsideTheBoundingSphereAreRefused) {
  EXPECT_THROW(validate_area_light({{-0.5, 0.5, -0.5}, {1, 0, 0}, {0, 0, 1}}, {0, 0, 0}, 1.0), InputError);
  // The plane's foot point is outside the rectangle, an edge passes through the sphere.
  EXPECT_THROW(validate_area_light({{0.5, 0.0, -3}, {0, 0, 6}, {0, 3, 0}}, {0, 0, 0}, 1.0), InputError);
  EXPECT_THROW(validate_area_light({{-1, 2, -1}, {1, 0, 0}, {2, 0, 0}}, {0, 0, 0}, 1.0), InputError);
  EXPECT_NO_THROW(validate_area_light({{-1, 2, -1}, {2, 0, 0}, {0, 0, 2}}, {0, 0, 0}, 1.0));
  AreaLight nan{{-1, 2, -1}, {2, 0, 0}, {0, 0, 2}};
  nan.radiance[1] = std::nan("");
  EXPECT_THROW(validate_area_light(nan, {0, 0, 0}, 1.0), InputError);
}

// --- the command -----------------------------------------------------------------------------

// A small .csm of the built-in sphere (8 x 8 views of 16 x 16 texels) and a sky, in `dir`.
void write_inputs(const std::string& dir) {
  const SceneGeometry object = load_coherent_object("sphere");
  co::StackLayout layout;
  layout.views_theta = layout.views_phi = 8;
  layout.resolution = 16;
  fit_bounding_sphere(object, layout);
  io::CoherentFile file;
  file.stack = ref::coherent::compress(render_stack(object, layout, 1));
  file.source = "sphere";
  io::write_coherent(dir + "/sphere.csm", file);
  SkyOptions sky;
  sky.width = 32;
  sky.height = 16;
  io::write_image(dir + "/sky.exr", synthetic_sky(sky));
}

TEST(CoherentRender, CommandWritesImageAndPreview) {
  const std::string dir = temp_dir("coherent_render_cli");
  write_inputs(dir);
  const RunResult r = run_cli("coherent render " + dir + "/sphere.csm --envmap " + dir + "/sky.exr -o " + dir +
                                  "/out.exr --width 24 --height 16 --samples 4 --preview "
                                  "--area-light -1 3 -1 2 0 0 0 0 2 5 --filter roulette --albedo 0.5 0.5 0.5 "
                                  "--specular 0.3 0.3 0.3 --shininess 50 --passes 2",
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("M samples/s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 passes of 4 samples"), std::string::npos) << r.out;
  ASSERT_TRUE(std::filesystem::exists(dir + "/out.exr"));
  ASSERT_TRUE(std::filesystem::exists(dir + "/out.png"));
  auto in = OIIO::ImageInput::open(dir + "/out.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 24);
  EXPECT_EQ(in->spec().nchannels, 3);
  std::vector<float> px(24 * 16 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data()));
  for (float v : px) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
  // The reference on the same samples runs too.
  EXPECT_EQ(run_cli("coherent render " + dir + "/sphere.csm --envmap " + dir + "/sky.exr -o " + dir +
                        "/ref.exr --width 8 --height 8 --samples 2 --reference embree -q",
                    dir)
                .exit_code,
            0);
  EXPECT_EQ(run_cli("coherent sky -o " + dir + "/gen.exr --width 16 --height 8", dir).exit_code, 0);
  // Two objects (the sphere twice), the second placed above and moving, a ground plane, 2 frames.
  const RunResult frames =
      run_cli("coherent render " + dir + "/sphere.csm " + dir + "/sphere.csm --envmap " + dir + "/sky.exr -o " + dir +
                  "/frame.exr --width 16 --height 16 --samples 2 "
                  "--place 2 0 3 0 --move 2 0.5 0 0 --spin 1 0 1 0 10 --frames 2 "
                  "--ground-plane -1.5 --camera-orbit 15",
              dir);
  ASSERT_EQ(frames.exit_code, 0) << frames.err;
  EXPECT_NE(frames.out.find("2 objects"), std::string::npos) << frames.out;
  // A fixed local light's cube maps, built and rendered with.
  const RunResult built = run_cli("coherent build sphere -o " + dir +
                                      "/light.csm --local-light -0.5 1.5 -0.5 1 0 0 0 "
                                      "0 1 --light-samples 2x2 --res 16 -q",
                                  dir);
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const RunResult info = run_cli("coherent info " + dir + "/light.csm", dir);
  EXPECT_NE(info.out.find("2x2 sampling points (4 cube maps, 24 maps)"), std::string::npos) << info.out;
  const RunResult lit = run_cli("coherent render " + dir + "/sphere.csm --local-light " + dir + "/light.csm " +
                                    "--local-radiance 3 --envmap " + dir + "/sky.exr -o " + dir +
                                    "/local.exr --width 12 --height 12 --samples 2",
                                dir);
  ASSERT_EQ(lit.exit_code, 0) << lit.err;
  EXPECT_NE(lit.out.find("+ local 1"), std::string::npos) << lit.out;
  // A mesh light (an OBJ quad in the object's frame) likewise.
  {
    std::ofstream obj(dir + "/lamp.obj");
    obj << "v -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\nv 0.5 1.5 0.5\nv -0.5 1.5 0.5\nf 1 2 3\nf 1 3 4\n";
  }
  const RunResult mesh_built = run_cli("coherent build sphere -o " + dir + "/lamp.csm --local-light-mesh " + dir +
                                           "/lamp.obj --light-samples 3x1 --res 16 -q",
                                       dir);
  ASSERT_EQ(mesh_built.exit_code, 0) << mesh_built.err;
  const RunResult mesh_lit =
      run_cli("coherent render " + dir + "/sphere.csm --local-light " + dir + "/lamp.csm " + "--envmap " + dir +
                  "/sky.exr -o " + dir + "/lamp.exr --width 12 --height 12 --samples 2 -q",
              dir);
  EXPECT_EQ(mesh_lit.exit_code, 0) << mesh_lit.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/frame_0000.exr"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/frame_0001.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/frame.exr"));
  EXPECT_NO_THROW(load_envmap(dir + "/gen.exr"));
}

TEST(CoherentRender, CommandRefusesBadInputWritingNothing) {
  const std::string dir = temp_dir("coherent_render_bad");
  write_inputs(dir);
  {
    std::ofstream cut(dir + "/cut.csm", std::ios::binary);
    std::ifstream whole(dir + "/sphere.csm", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
    cut << bytes.substr(0, bytes.size() / 2);
  }
  std::filesystem::copy_file(dir + "/sky.exr", dir + "/cut.exr");
  std::filesystem::resize_file(dir + "/cut.exr", std::filesystem::file_size(dir + "/sky.exr") / 2);
  const std::string csm = dir + "/sphere.csm", env = " --envmap " + dir + "/sky.exr";
  const std::string out = " -o " + dir + "/out.exr --width 8 --height 8 --samples 2";
  const std::vector<std::string> bad = {
      dir + "/missing.csm" + env + out,
      dir + "/cut.csm" + env + out,
      csm + " --envmap " + dir + "/cut.exr" + out,
      csm + env + " -o " + dir + "/out.exr --samples 0",
      csm + env + out + " --camera-fov nan",
      csm + env + out + " --area-light 0 0 0 0.5 0 0 0 0 0.5 1",  // inside the bounding sphere
      csm + env + out + " --mesh box",                            // not the object of the stack
      csm + env + out + " --specular 0.5 0.5 0.5",                // albedo 0.8 + 0.5 > 1
      csm + env + out + " --specular 0.1 nan 0.1",
      csm + env + out + " --shininess -1",
      csm + env + out + " --passes 0",
      csm + env + out + " --time-budget -1",
      csm + env + out + " --time-budget inf",
      csm + env + out + " --filter bilinear",
      csm + env + out + " --filter roulette --reference embree",
      csm + " " + csm + env + out + " --place 3 0 3 0",    // no object 3
      csm + " " + csm + env + out + " --place 1.5 0 3 0",  // not an object number
      csm + " " + csm + env + out + " --mesh sphere",      // one mesh for two files
      csm + env + out + " --frames 0",
      csm + env + out + " --spin 1 0 0 0 10",  // no axis
      csm + env + out + " --rotate 1 0 1 0 inf",
      csm + env + out + " --ground-albedo 2 0 0 --ground-plane -1",
      csm + env + out + " --local-light " + csm,  // distant views, not cube maps
      // The light lies outside object 2 at frame 0, and inside it at frame 1.
      csm + " " + csm + env + out + " --place 2 0 4 0 --move 2 0 2 0 --frames 2 --area-light -1 6 -1 2 0 0 0 0 2 5",
  };
  for (const std::string& args : bad) {
    const RunResult r = run_cli("coherent render " + args, dir);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out.exr")) << args;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out.png")) << args;
  }
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 4u);  // the inputs alone: no temporary left behind
}

}  // namespace
}  // namespace sf::test

#pragma once
// Direct lighting of one object with its coherent shadow map (Ritschel 2007 sec. 5;
// docs/coherent_render.md): a G-buffer from Embree camera rays, then per pixel S stratified samples
// of a lat-long environment map and of rectangular semi-local area lights, diffuse or glossy
// (modified Phong, one-sample MIS between the map and the lobe), progressive passes (sec. 5.2). The
// visibility of every sample comes from the coherent maps on the device
// (render_coherent, kernels/coherent/render.cl) or, for the reference, from a host twin of the
// same sampler with the same random numbers and Embree occlusion rays (render_traced): the two
// differ by the coherent maps' discretisation alone.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "shadowfilter/coherent.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/runtime.hpp"

#include "envmap.hpp"
#include "ray_tracer.hpp"
#include "scene_geometry.hpp"
#include "scene_views.hpp"

namespace sf::scene {

// A two-sided rectangle (parallelogram) corner + s edge_a + t edge_b, s, t in [0, 1], emitting
// `radiance` (RGB) from both faces. Semi-local (seed sec. 4.3): the coherent maps only knows the object
// from outside, so the light must lie outside its convex hull; lights that reach into the
// bounding sphere are refused.
struct AreaLight {
  Vec3 corner, edge_a, edge_b;
  Vec3 radiance{1.0, 1.0, 1.0};
};
// InputError (one line) on a non-finite or degenerate rectangle, a negative or non-finite or larger
// than kMaxRadiance radiance, or a rectangle closer than `radius` to `center`.
void validate_area_light(const AreaLight& light, Vec3 center, double radius);

// A camera that frames the bounding sphere: from above the front (+z, a little up), looking at the
// centre, the sphere filling about 80% of the vertical field of view.
PerspectiveCamera framing_camera(Vec3 center, double radius, int width, int height, double fov_degrees);

// The G-buffer: 4 floats a pixel each. position: the shading point, lifted kLift times the
// bounding radius along the normal (both renders start their visibility tests there; Embree's
// rays need it to leave the surface), w = 1 on the object and 0 on background. normal: the unit
// geometric normal facing the camera, or on background the camera ray's direction. albedo: RGB.
struct GBuffer {
  int width = 0, height = 0;
  std::vector<float> position, normal, albedo;
  std::array<float, 3> eye{0.0f, 0.0f, 0.0f};  // the camera's position (glossy BRDFs' view direction)
  size_t hits = 0;                             // pixels on the object
  size_t pixels() const { return size_t(width) * size_t(height); }
};
inline constexpr double kLift = 1e-4;
// Camera rays through pixel centres, rows spread over `threads` threads (0: all cores).
GBuffer render_gbuffer(const RayTracer& object, const PerspectiveCamera& camera, double radius,
                       const std::array<float, 3>& albedo, int threads = 0);
// The same with an albedo per geometry (Hit::object: the meshes, then the spheres).
GBuffer render_gbuffer(const RayTracer& scene, const PerspectiveCamera& camera, double radius,
                       const std::vector<std::array<float, 3>>& albedo_of_geometry, int threads = 0);

// The visibility lookup of the coherent-map render (Ritschel 2007 sec. 4.5): the nearest view
// and texel (0 or 1); generalized PCF of the 2x2 nearest views' 2x2 texels (16 tests, fractional);
// or Russian roulette, one of those 16 drawn with its PCF weight as probability (one test, 0 or
// 1, PCF's value in expectation). The host twin passes the roulette's numbers to its Visibility.
enum class VisibilityFilter { Nearest = 0, Pcf = 1, Roulette = 2 };

struct RenderSettings {
  int samples = 16;   // S: env samples per pixel, and S samples per area light
  uint32_t seed = 1;  // the counter-based RNG's seed (the same seed gives the same numbers)
  std::vector<AreaLight> lights;
  int threads = 0;  // host renders: 0 = all cores
  VisibilityFilter filter = VisibilityFilter::Nearest;
  // Modified Phong: pi f = albedo + specular (n + 2) / 2 max(0, R.w)^n, n = shininess. specular
  // 0 is the diffuse BRDF (environment by light sampling alone); otherwise the environment
  // sample is drawn from the map or from the lobe (one-sample MIS, balance heuristic).
  std::array<float, 3> specular{0.0f, 0.0f, 0.0f};
  float shininess = 32.0f;
  // Progressive rendering (seed sec. 5.2): up to `passes` passes of S samples, each with its own
  // seed (pass_seed), the image the mean of the passes so far; with time_budget > 0 (seconds) the
  // render also stops before a pass that would end past the budget (at least one pass runs).
  int passes = 1;
  double time_budget = 0.0;
  // A fixed local light (seed sec. 4.2): a rectangle (sampled uniformly; the cube map of the
  // sample's grid cell answers its visibility) or a mesh light (a sample is one of its sampling
  // points, each standing for area / count of the mesh, with its normal), and its radiance;
  // render_coherent takes its depth cube maps beside.
  struct LocalLightSource {
    coherent::LocalLight light;
    Vec3 radiance{1.0, 1.0, 1.0};
  };
  std::optional<LocalLightSource> local_light;
};
// InputError unless 1 <= samples <= kMaxSamples, at most kMaxLights lights, specular within [0, 1],
// shininess within [0, kMaxShininess], 1 <= passes <= kMaxPasses and time_budget finite and >= 0.
inline constexpr int kMaxSamples = 1 << 20;
inline constexpr int kMaxLights = 64;
inline constexpr int kMaxPasses = 1 << 16;
inline constexpr float kMaxShininess = 1e4f;
void validate(const RenderSettings& settings);
// The Latin hypercube's second stride: coprime to S, near S / golden ratio (coherent/render.cl).
uint32_t sample_stride(uint32_t samples);
// The seed of progressive pass m: the settings' seed for pass 0, a hash of both after it.
uint32_t pass_seed(uint32_t seed, int pass);

// What a render did: its wall time (the device render alone: built program, uploaded inputs) and
// the passes it ran.
struct RenderStats {
  double seconds = 0.0;
  int passes = 0;
};

// The host twin of coherent/render.cl: the same samples and float arithmetic, visibility from
// `visible(query)`: the fraction of the segment p + t d, t in (0, t_max), that is free (d unit
// length; 0 or 1 for a ray, fractional for a PCF lookup). r holds the sample's four roulette
// numbers when settings.filter is Roulette (else zeros); light is -1 for the environment, l for
// area light l, and settings.lights.size() for the local light, whose sample is (u, v) (on its
// rectangle; for a mesh light, point min(u count, count - 1)).
struct VisibilityQuery {
  std::array<float, 3> p, d;
  float t_max = 0.0f;
  std::array<float, 4> r{0.0f, 0.0f, 0.0f, 0.0f};
  int light = -1;
  float u = 0.0f, v = 0.0f;
};
using Visibility = std::function<float(const VisibilityQuery& query)>;
HostImage render_host(const GBuffer& g, const EnvMap& env, const RenderSettings& settings, const Visibility& visible,
                      RenderStats* stats = nullptr);
// render_host with Embree occlusion rays against the occluders (kMaskOccluders: geometry marked
// ground receives and does not occlude, as a receiver without maps): the reference of the same
// samples (settings.filter plays no part: a ray has no filter).
HostImage render_traced(const RayTracer& object, const GBuffer& g, const EnvMap& env, const RenderSettings& settings,
                        RenderStats* stats = nullptr);

// Where an object stands (seed sec. 4.6): object to world, x_world = rotation x_object +
// translation, the rotation orthonormal (row-major). Its maps answer queries in the object's
// frame: D' = D T^-1.
struct RigidTransform {
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};
  Vec3 translation{0.0, 0.0, 0.0};
  Vec3 apply(Vec3 p) const;
  Vec3 rotate(Vec3 d) const;
  // This transform, then `next`.
  RigidTransform then(const RigidTransform& next) const;
};
// A rotation by `degrees` about the axis through `pivot` (right-handed); InputError (naming
// `what`) for a zero or non-finite axis or a non-finite angle or pivot.
RigidTransform rotation_about(Vec3 axis, double degrees, Vec3 pivot, const std::string& what);
RigidTransform translation_by(Vec3 t);

// The world-to-object transform as the kernel takes it: three rows of 4 floats (the inverse
// rotation's row, the inverse translation's component), and the same float arithmetic on the
// host (the twins of render.cl's sf_scene_visibility).
using ObjectRows = std::array<float, 12>;
ObjectRows object_rows(const RigidTransform& transform);
std::array<float, 3> to_object_point(const ObjectRows& rows, const std::array<float, 3>& p);
std::array<float, 3> to_object_direction(const ObjectRows& rows, const std::array<float, 3>& d);

// One object of the render: its compressed maps (the caller's, alive through the call) and its
// placement.
struct PlacedStack {
  const coherent::CompressedStack* stack = nullptr;
  RigidTransform transform;
};

// The device render with the compressed visibility through settings.filter: the visibility of a
// sample is the product over the objects of its visibility in each object's maps (seed sec.
// 4.6: objects shadow each other and themselves; receivers without maps, such as ground planes,
// take their shadows and cast none). At most kMaxObjects objects.
inline constexpr int kMaxObjects = 64;
// With settings.local_light, `local_maps` holds its depth cube maps (coherent::cube_layout of the
// light; InputError otherwise); the local light's visibility is its cube maps' alone (the object
// they were built around, unmoved).
HostImage render_coherent(Runtime& rt, const std::vector<PlacedStack>& objects, const GBuffer& g, const EnvMap& env,
                          const RenderSettings& settings, RenderStats* stats = nullptr,
                          const coherent::CompressedStack* local_maps = nullptr);
// One object where its maps were built (the identity transform).
HostImage render_coherent(Runtime& rt, const coherent::CompressedStack& stack, const GBuffer& g, const EnvMap& env,
                          const RenderSettings& settings, RenderStats* stats = nullptr);

// Visibility queries a render makes at most in `passes` passes: pixels on the object x S x
// (1 + lights) a pass (samples below the horizon of the normal skip their query).
inline double render_queries(const GBuffer& g, const EnvMap& env, const RenderSettings& s, int passes = 1) {
  return double(g.hits) * s.samples * ((env.sampled ? 1 : 0) + double(s.lights.size()) + (s.local_light ? 1 : 0)) *
         passes;
}

// Root mean square difference of two RGB images over the pixels where mask (a G-buffer) is on the
// object, over all three channels.
double rmse_on_object(const HostImage& a, const HostImage& b, const GBuffer& mask);

}  // namespace sf::scene

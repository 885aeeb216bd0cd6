#include "coherent_render.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Rows spread over threads, each pixel computed on its own: the result does not depend on the
// thread count.
template <class RowFn>
void for_each_row(int rows, int threads, const RowFn& row_fn) {
  int workers = threads > 0 ? threads : int(std::thread::hardware_concurrency());
  workers = std::max(1, std::min(rows, workers));
  std::atomic<int> next{0};
  auto work = [&] {
    for (int y = next++; y < rows; y = next++) row_fn(y);
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Distance from point c to the segment a + s e, s in [0, 1].
double segment_distance(Vec3 c, Vec3 a, Vec3 e) {
  const double s = std::clamp(dot(c - a, e) / dot(e, e), 0.0, 1.0);
  return length(c - (a + s * e));
}

// --- the host twin of coherent/render.cl (same integer hashing, same float operations) ------------

using F3 = std::array<float, 3>;

uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

float rand01(uint32_t seed, uint32_t dim, uint32_t pixel, uint32_t sample) {
  uint32_t h = hash32(seed + 0x9e3779b9u * dim);
  h = hash32(h ^ pixel);
  h = hash32(h ^ sample);
  return float(h >> 8) * (1.0f / 16777216.0f);
}

constexpr uint32_t kRotation = 0xffffffffu;
constexpr float kBelowOne = 0x1.fffffep-1f;

void stratified(uint32_t seed, uint32_t k, uint32_t pixel, uint32_t s, uint32_t S, float inv_s, uint32_t stride,
                float* u_out, float* v_out) {
  const float r0 = rand01(seed, 4u * k, pixel, kRotation);
  const float r1 = rand01(seed, 4u * k + 1u, pixel, kRotation);
  const float j0 = rand01(seed, 4u * k + 2u, pixel, s);
  const float j1 = rand01(seed, 4u * k + 3u, pixel, s);
  const uint32_t t = uint32_t((uint64_t(s) * uint64_t(stride)) % uint64_t(S));
  float u = (float(s) + j0) * inv_s + r0;
  float v = (float(t) + j1) * inv_s + r1;
  u -= std::floor(u);
  v -= std::floor(v);
  *u_out = std::min(u, kBelowOne);
  *v_out = std::min(v, kBelowOne);
}

float dot3(const F3& a, const F3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// coherent/render.cl's constants and glossy helpers, operation for operation.
constexpr uint32_t kRouletteDim = 1024u;
constexpr uint32_t kChoiceDim = 4096u;
constexpr float kPiF = 3.14159265358979f;

float phong_cos(const F3& R, const F3& w) { return std::max(dot3(R, w), 0.0f); }
F3 phong_pi_f(const F3& albedo, const F3& ks, float n, const F3& R, const F3& w) {
  const float lobe = (n + 2.0f) * 0.5f * std::pow(phong_cos(R, w), n);
  return {albedo[0] + ks[0] * lobe, albedo[1] + ks[1] * lobe, albedo[2] + ks[2] * lobe};
}
float phong_pdf(float n, const F3& R, const F3& w) { return (n + 1.0f) * (0.5f / kPiF) * std::pow(phong_cos(R, w), n); }
F3 phong_sample(float n, const F3& R, float u, float v) {
  const float sign = std::copysign(1.0f, R[2]);
  const float a = -1.0f / (sign + R[2]);
  const float b = R[0] * R[1] * a;
  const F3 T{1.0f + sign * R[0] * R[0] * a, sign * b, -sign * R[0]};
  const F3 B{b, sign + R[1] * R[1] * a, -R[1]};
  const float ca = std::pow(u, 1.0f / (n + 1.0f));
  const float sa = std::sqrt(std::max(0.0f, 1.0f - ca * ca));
  const float phi = 2.0f * kPiF * v;
  const float x = sa * std::cos(phi), y = sa * std::sin(phi);
  F3 w;
  for (int k = 0; k < 3; ++k) w[k] = T[k] * x + B[k] * y + R[k] * ca;
  return w;
}

}  // namespace

void validate_area_light(const AreaLight& l, Vec3 center, double radius) {
  if (!finite(l.corner) || !finite(l.edge_a) || !finite(l.edge_b))
    throw InputError("--area-light: corner and edges must be finite");
  for (int c = 0; c < 3; ++c)
    if (const double r = l.radiance[c]; !std::isfinite(r) || r < 0.0 || r > kMaxRadiance)
      throw InputError("--area-light: radiance must be finite, >= 0 and <= 1e20");
  const Vec3 n = cross(l.edge_a, l.edge_b);
  if (!(length(n) > 1e-12 * std::max(1.0, dot(l.edge_a, l.edge_a) + dot(l.edge_b, l.edge_b))))
    throw InputError("--area-light: the edges span no area (zero or parallel)");
  // The closest point of the parallelogram to the centre: the plane's foot point when it lies
  // inside, else a point of one of the four sides.
  const Vec3 un = normalize(n);
  const Vec3 foot = center - dot(center - l.corner, un) * un;
  // (s, t) of the foot point in the edges' basis (Gram matrix solve).
  const double aa = dot(l.edge_a, l.edge_a), ab = dot(l.edge_a, l.edge_b), bb = dot(l.edge_b, l.edge_b);
  const Vec3 r = foot - l.corner;
  const double ra = dot(r, l.edge_a), rb = dot(r, l.edge_b), det = aa * bb - ab * ab;
  const double s = (ra * bb - rb * ab) / det, t = (rb * aa - ra * ab) / det;
  double dist;
  if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0)
    dist = std::fabs(dot(center - l.corner, un));
  else
    dist = std::min({segment_distance(center, l.corner, l.edge_a), segment_distance(center, l.corner, l.edge_b),
                     segment_distance(center, l.corner + l.edge_a, l.edge_b),
                     segment_distance(center, l.corner + l.edge_b, l.edge_a)});
  if (!(dist > radius))
    throw InputError("--area-light: the light reaches into the object's bounding sphere (distance " +
                     std::to_string(dist) + " from its centre, radius " + std::to_string(radius) +
                     "); semi-local lights must lie outside the object");
}

PerspectiveCamera framing_camera(Vec3 center, double radius, int width, int height, double fov_degrees) {
  PerspectiveCamera cam;
  cam.width = width;
  cam.height = height;
  cam.vertical_fov_degrees = fov_degrees;
  // The sphere's angular radius is asin(radius / distance); 0.8 of the half field of view.
  const double half = 0.8 * 0.5 * fov_degrees * kPi / 180.0;
  const double distance = radius / std::sin(half);
  cam.position = center + distance * normalize(Vec3{0.0, 0.35, 1.0});
  cam.target = center;
  return cam;
}

GBuffer render_gbuffer(const RayTracer& object, const PerspectiveCamera& camera, double radius,
                       const std::vector<std::array<float, 3>>& albedo_of_geometry, int threads) {
  if (albedo_of_geometry.empty()) throw InputError("render_gbuffer: no albedo given");
  GBuffer g;
  g.width = camera.width;
  g.height = camera.height;
  g.position.assign(g.pixels() * 4, 0.0f);
  g.normal.assign(g.pixels() * 4, 0.0f);
  g.albedo.assign(g.pixels() * 4, 0.0f);
  g.eye = {float(camera.position.x), float(camera.position.y), float(camera.position.z)};
  std::atomic<size_t> hits{0};
  const double lift = kLift * radius;
  for_each_row(g.height, threads, [&](int y) {
    size_t row_hits = 0;
    for (int x = 0; x < g.width; ++x) {
      const size_t i = size_t(y) * g.width + x;
      const Ray ray = camera.ray_through(x + 0.5, y + 0.5);
      const auto hit = object.closest(ray, 0.0, std::numeric_limits<double>::infinity());
      float* P = &g.position[4 * i];
      float* N = &g.normal[4 * i];
      if (!hit) {
        N[0] = float(ray.direction.x);
        N[1] = float(ray.direction.y);
        N[2] = float(ray.direction.z);
        continue;
      }
      const Vec3 p = ray.at(hit->t) + lift * hit->normal;
      P[0] = float(p.x);
      P[1] = float(p.y);
      P[2] = float(p.z);
      P[3] = 1.0f;
      N[0] = float(hit->normal.x);
      N[1] = float(hit->normal.y);
      N[2] = float(hit->normal.z);
      const std::array<float, 3>& albedo =
          albedo_of_geometry[std::min<size_t>(hit->object, albedo_of_geometry.size() - 1)];
      for (int c = 0; c < 3; ++c) g.albedo[4 * i + c] = albedo[c];
      g.albedo[4 * i + 3] = 1.0f;
      ++row_hits;
    }
    hits += row_hits;
  });
  g.hits = hits;
  return g;
}

GBuffer render_gbuffer(const RayTracer& object, const PerspectiveCamera& camera, double radius,
                       const std::array<float, 3>& albedo, int threads) {
  return render_gbuffer(object, camera, radius, std::vector<std::array<float, 3>>{albedo}, threads);
}

Vec3 RigidTransform::rotate(Vec3 d) const {
  const auto& r = rotation;
  return {r[0] * d.x + r[1] * d.y + r[2] * d.z, r[3] * d.x + r[4] * d.y + r[5] * d.z,
          r[6] * d.x + r[7] * d.y + r[8] * d.z};
}

Vec3 RigidTransform::apply(Vec3 p) const { return rotate(p) + translation; }

RigidTransform RigidTransform::then(const RigidTransform& next) const {
  RigidTransform out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0.0;
      for (int k = 0; k < 3; ++k) v += next.rotation[3 * i + k] * rotation[3 * k + j];
      out.rotation[3 * i + j] = v;
    }
  out.translation = next.apply(translation);
  return out;
}

RigidTransform rotation_about(Vec3 axis, double degrees, Vec3 pivot, const std::string& what) {
  if (!finite(axis) || !finite(pivot) || !std::isfinite(degrees))
    throw InputError(what + ": the axis, angle and pivot must be finite");
  const double len = length(axis);
  if (!(len > 1e-12)) throw InputError(what + ": the rotation axis must not be zero");
  const Vec3 a = (1.0 / len) * axis;
  const double t = degrees * kPi / 180.0, c = std::cos(t), s = std::sin(t), C = 1.0 - c;
  RigidTransform r;
  r.rotation = {c + a.x * a.x * C,       a.x * a.y * C - a.z * s, a.x * a.z * C + a.y * s,
                a.y * a.x * C + a.z * s, c + a.y * a.y * C,       a.y * a.z * C - a.x * s,
                a.z * a.x * C - a.y * s, a.z * a.y * C + a.x * s, c + a.z * a.z * C};
  r.translation = pivot - r.rotate(pivot);
  return r;
}

RigidTransform translation_by(Vec3 t) {
  RigidTransform r;
  r.translation = t;
  return r;
}

ObjectRows object_rows(const RigidTransform& t) {
  // Inverse: x_object = R^T (x_world - t) = R^T x_world - R^T t.
  const auto& r = t.rotation;
  ObjectRows rows{};
  for (int i = 0; i < 3; ++i) {
    const Vec3 col{r[i], r[3 + i], r[6 + i]};  // row i of R^T
    rows[4 * i] = float(col.x);
    rows[4 * i + 1] = float(col.y);
    rows[4 * i + 2] = float(col.z);
    rows[4 * i + 3] = float(-dot(col, t.translation));
  }
  return rows;
}

std::array<float, 3> to_object_point(const ObjectRows& m, const std::array<float, 3>& p) {
  std::array<float, 3> out;
  for (int i = 0; i < 3; ++i) out[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3];
  return out;
}

std::array<float, 3> to_object_direction(const ObjectRows& m, const std::array<float, 3>& d) {
  std::array<float, 3> out;
  for (int i = 0; i < 3; ++i) out[i] = m[4 * i] * d[0] + m[4 * i + 1] * d[1] + m[4 * i + 2] * d[2];
  return out;
}

void validate(const RenderSettings& s) {
  if (s.samples < 1 || s.samples > kMaxSamples)
    throw InputError("--samples must be in [1, " + std::to_string(kMaxSamples) + "], got " + std::to_string(s.samples));
  if (s.lights.size() > size_t(kMaxLights))
    throw InputError("at most " + std::to_string(kMaxLights) + " area lights, got " + std::to_string(s.lights.size()));
  for (float k : s.specular)
    if (!(k >= 0.0f && k <= 1.0f)) throw InputError("--specular must be within [0, 1]");
  if (!(s.shininess >= 0.0f && s.shininess <= kMaxShininess))
    throw InputError("--shininess must be within [0, " + std::to_string(int(kMaxShininess)) + "]");
  if (s.passes < 1 || s.passes > kMaxPasses)
    throw InputError("--passes must be in [1, " + std::to_string(kMaxPasses) + "], got " + std::to_string(s.passes));
  if (!(std::isfinite(s.time_budget) && s.time_budget >= 0.0))
    throw InputError("--time-budget must be finite and >= 0 seconds");
}

uint32_t pass_seed(uint32_t seed, int pass) {
  return pass == 0 ? seed : hash32(hash32(seed) ^ hash32(0x85ebca6bu + uint32_t(pass)));
}

uint32_t sample_stride(uint32_t S) {
  if (S <= 2) return 1;
  uint32_t k = std::max<uint32_t>(1, uint32_t(std::lround(S * 0.6180339887498949)));
  auto gcd = [](uint32_t a, uint32_t b) {
    while (b) {
      const uint32_t t = a % b;
      a = b;
      b = t;
    }
    return a;
  };
  while (gcd(k, S) != 1) ++k;
  return k % S;
}

namespace {

// The progressive loop both renders share: pass after pass until `passes` ran or the next pass
// would end past the time budget (the mean pass time so far predicts it); at least one pass.
template <class PassFn>
void run_passes(const RenderSettings& settings, RenderStats* stats, const PassFn& pass_fn) {
  const auto start = std::chrono::steady_clock::now();
  int done = 0;
  double elapsed = 0.0;
  while (done < settings.passes) {
    pass_fn(done);
    ++done;
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (settings.time_budget > 0.0 && elapsed + elapsed / done > settings.time_budget) break;
  }
  if (stats) *stats = {elapsed, done};
}

}  // namespace

HostImage render_host(const GBuffer& g, const EnvMap& env, const RenderSettings& settings, const Visibility& visible,
                      RenderStats* stats) {
  validate(settings);
  const uint32_t S = uint32_t(settings.samples), stride = sample_stride(S);
  const float inv_s = 1.0f / float(S);
  const bool roulette = settings.filter == VisibilityFilter::Roulette;
  const F3 ks = settings.specular;
  const float shine = settings.shininess;
  const bool glossy = ks[0] > 0.0f || ks[1] > 0.0f || ks[2] > 0.0f;
  // The lights as the kernel reads them (float).
  struct FL {
    F3 corner, ea, eb, radiance;
  };
  std::vector<FL> lights;
  // The local light last: the kernel draws it as pair 1 + the area lights' count, with the area
  // lights' arithmetic (only its visibility differs, and that is `visible`'s).
  std::vector<AreaLight> all = settings.lights;
  const coherent::LocalLight* local = settings.local_light ? &settings.local_light->light : nullptr;
  if (local && !local->is_mesh())
    all.push_back({local->corner, local->edge_a, local->edge_b, settings.local_light->radiance});
  // A mesh light's points, normals and radiance as the kernel reads them.
  std::vector<F3> mesh_points, mesh_normals;
  F3 mesh_radiance{0.0f, 0.0f, 0.0f};
  float mesh_area = 0.0f;
  if (local && local->is_mesh()) {
    for (size_t k = 0; k < local->points.size(); ++k) {
      const Vec3 &q = local->points[k], &n = local->normals[k];
      mesh_points.push_back({float(q.x), float(q.y), float(q.z)});
      mesh_normals.push_back({float(n.x), float(n.y), float(n.z)});
    }
    const Vec3& r = settings.local_light->radiance;
    mesh_radiance = {float(r.x), float(r.y), float(r.z)};
    mesh_area = float(local->area);
  }
  for (const AreaLight& l : all)
    lights.push_back({{float(l.corner.x), float(l.corner.y), float(l.corner.z)},
                      {float(l.edge_a.x), float(l.edge_a.y), float(l.edge_a.z)},
                      {float(l.edge_b.x), float(l.edge_b.y), float(l.edge_b.z)},
                      {float(l.radiance[0]), float(l.radiance[1]), float(l.radiance[2])}});
  HostImage out(g.width, g.height, 3);
  out.channel_names = {"R", "G", "B"};
  const float inf = std::numeric_limits<float>::infinity();
  // One pixel's estimate with the pass's seed.
  auto shade = [&](size_t i, uint32_t seed) -> F3 {
    const float* P = &g.position[4 * i];
    const F3 N{g.normal[4 * i], g.normal[4 * i + 1], g.normal[4 * i + 2]};
    const F3 albedo{g.albedo[4 * i], g.albedo[4 * i + 1], g.albedo[4 * i + 2]};
    const F3 p{P[0], P[1], P[2]};
    const uint32_t pixel = uint32_t(i);
    F3 R = N;
    float q = 1.0f;
    if (glossy) {
      const F3 e{g.eye[0] - p[0], g.eye[1] - p[1], g.eye[2] - p[2]};
      const float len = std::sqrt(dot3(e, e));
      const F3 wo{e[0] / len, e[1] / len, e[2] / len};
      const float twice = 2.0f * dot3(N, wo);
      R = {N[0] * twice - wo[0], N[1] * twice - wo[1], N[2] * twice - wo[2]};
      const float ld = 0.2126f * albedo[0] + 0.7152f * albedo[1] + 0.0722f * albedo[2];
      const float ls = 0.2126f * ks[0] + 0.7152f * ks[1] + 0.0722f * ks[2];
      q = std::clamp(ld / (ld + ls), 0.25f, 0.75f);
    }
    // The roulette's numbers of query pair k in sample s (zeros for the other filters).
    auto numbers = [&](uint32_t k, uint32_t s) {
      std::array<float, 4> r{0.0f, 0.0f, 0.0f, 0.0f};
      if (roulette)
        for (uint32_t j = 0; j < 4; ++j) r[j] = rand01(seed, kRouletteDim + 4u * k + j, pixel, s);
      return r;
    };
    F3 sum{0.0f, 0.0f, 0.0f};
    // A light sample's radiance times its weight f, through the glossy BRDF where there is one
    // (the diffuse albedo / pi comes at the end), as render.cl adds it.
    auto add_light = [&](const F3& radiance, float f, const F3& w) {
      if (glossy) {
        const F3 b = phong_pi_f(albedo, ks, shine, R, w);
        for (int k = 0; k < 3; ++k) sum[k] += radiance[k] * f * b[k];
      } else {
        for (int k = 0; k < 3; ++k) sum[k] += radiance[k] * f;
      }
    };
    for (uint32_t s = 0; s < S; ++s) {
      if (env.sampled && !glossy) {
        float u, v;
        stratified(seed, 0u, pixel, s, S, inv_s, stride, &u, &v);
        const EnvSample e = sample_envmap(env, u, v);
        const float c = dot3(N, e.dir);
        if (c > 0.0f) {
          const float vis = visible({p, e.dir, inf, numbers(0u, s)});
          if (vis > 0.0f) {
            const F3 L = env.texel(e.x, e.y);
            const float w = vis * c / e.pdf;
            for (int k = 0; k < 3; ++k) sum[k] += L[k] * w;
          }
        }
      } else if (env.sampled) {
        float u, v;
        stratified(seed, 0u, pixel, s, S, inv_s, stride, &u, &v);
        F3 w;
        int tx, ty;
        float pdf_env;
        if (rand01(seed, kChoiceDim, pixel, s) < q) {
          const EnvSample e = sample_envmap(env, u, v);
          w = e.dir;
          tx = e.x;
          ty = e.y;
          pdf_env = e.pdf;
        } else {
          w = phong_sample(shine, R, u, v);
          envmap_texel_of(env, w, &tx, &ty);
          pdf_env = envmap_pdf(env, tx, ty);
        }
        const float c = dot3(N, w);
        const float pdf = q * pdf_env + (1.0f - q) * phong_pdf(shine, R, w);
        if (c > 0.0f && pdf > 0.0f) {
          const float vis = visible({p, w, inf, numbers(0u, s)});
          if (vis > 0.0f) {
            const F3 L = env.texel(tx, ty);
            const F3 f = phong_pi_f(albedo, ks, shine, R, w);
            const float weight = vis * c / pdf;
            for (int k = 0; k < 3; ++k) sum[k] += L[k] * f[k] * weight;
          }
        }
      }
      for (size_t l = 0; l < lights.size(); ++l) {
        const FL& li = lights[l];
        float u, v;
        stratified(seed, 1u + uint32_t(l), pixel, s, S, inv_s, stride, &u, &v);
        F3 d;
        for (int k = 0; k < 3; ++k) d[k] = li.corner[k] + li.ea[k] * u + li.eb[k] * v - p[k];
        const float dist2 = dot3(d, d);
        const F3 nl{li.ea[1] * li.eb[2] - li.ea[2] * li.eb[1], li.ea[2] * li.eb[0] - li.ea[0] * li.eb[2],
                    li.ea[0] * li.eb[1] - li.ea[1] * li.eb[0]};
        const float area = std::sqrt(dot3(nl, nl));
        const float dist = std::sqrt(dist2);
        const F3 w{d[0] / dist, d[1] / dist, d[2] / dist};
        const float c = dot3(N, w);
        const float cl = std::fabs(dot3(nl, w)) / area;
        // render.cl's sf_rect_sample: the sample's weight, 0 facing away or edge-on.
        const float g = c > 0.0f && cl > 0.0f && dist2 > 0.0f ? c * cl * area / dist2 : 0.0f;
        if (g > 0.0f) {
          VisibilityQuery query{p, w, dist, numbers(1u + uint32_t(l), s)};
          query.light = int(l);
          query.u = u;
          query.v = v;
          const float vis = visible(query);
          if (vis > 0.0f) add_light(li.radiance, vis * g, w);
        }
      }
      if (!mesh_points.empty()) {
        // The mesh light: sampling point j of the pair's first number, standing for area / count.
        float u, v;
        stratified(seed, 1u + uint32_t(lights.size()), pixel, s, S, inv_s, stride, &u, &v);
        const int count = int(mesh_points.size());
        const int j = std::min(int(u * float(count)), count - 1);
        const F3& sp = mesh_points[size_t(j)];
        const F3& nl = mesh_normals[size_t(j)];
        const F3 d{sp[0] - p[0], sp[1] - p[1], sp[2] - p[2]};
        const float dist2 = dot3(d, d);
        const float dist = std::sqrt(dist2);
        const F3 w{d[0] / dist, d[1] / dist, d[2] / dist};
        const float c = dot3(N, w);
        const float cl = std::fabs(dot3(nl, w));
        if (c > 0.0f && cl > 0.0f && dist2 > 0.0f) {
          VisibilityQuery query{p, w, dist, numbers(1u + uint32_t(lights.size()), s)};
          query.light = int(lights.size());
          query.u = u;
          query.v = v;
          const float vis = visible(query);
          if (vis > 0.0f) add_light(mesh_radiance, vis * (c * cl * mesh_area / dist2), w);
        }
      }
    }
    const float scale = 0.31830988618379067f * inv_s;
    F3 value;
    for (int k = 0; k < 3; ++k) value[k] = glossy ? sum[k] * scale : albedo[k] * scale * sum[k];
    return value;
  };
  run_passes(settings, stats, [&](int pass) {
    const uint32_t seed = pass_seed(settings.seed, pass);
    for_each_row(g.height, settings.threads, [&](int y) {
      for (int x = 0; x < g.width; ++x) {
        const size_t i = size_t(y) * g.width + x;
        if (g.position[4 * i + 3] == 0.0f) {
          int tx, ty;
          envmap_texel_of(env, {g.normal[4 * i], g.normal[4 * i + 1], g.normal[4 * i + 2]}, &tx, &ty);
          const F3 c = env.texel(tx, ty);
          for (int k = 0; k < 3; ++k) out.at(x, y, k) = c[k];
          continue;
        }
        const F3 value = shade(i, seed);
        for (int k = 0; k < 3; ++k) {
          float& o = out.at(x, y, k);
          o = pass == 0 ? value[k] : o + (value[k] - o) / float(pass + 1);
        }
      }
    });
  });
  return out;
}

HostImage render_traced(const RayTracer& object, const GBuffer& g, const EnvMap& env, const RenderSettings& settings,
                        RenderStats* stats) {
  return render_host(
      g, env, settings,
      [&](const VisibilityQuery& q) {
        const Ray ray{{q.p[0], q.p[1], q.p[2]}, normalize(Vec3{q.d[0], q.d[1], q.d[2]})};
        const double reach = std::isinf(q.t_max) ? std::numeric_limits<double>::infinity() : double(q.t_max);
        // Occluders only: ground planes are receivers without maps (coherent_scene.hpp).
        return object.occluded(ray, 0.0, reach, kMaskOccluders) ? 0.0f : 1.0f;
      },
      stats);
}

HostImage render_coherent(Runtime& rt, const coherent::CompressedStack& stack, const GBuffer& g, const EnvMap& env,
                          const RenderSettings& settings, RenderStats* stats) {
  return render_coherent(rt, std::vector<PlacedStack>{{&stack, RigidTransform{}}}, g, env, settings, stats);
}

HostImage render_coherent(Runtime& rt, const std::vector<PlacedStack>& objects, const GBuffer& g, const EnvMap& env,
                          const RenderSettings& settings, RenderStats* stats,
                          const coherent::CompressedStack* local_maps) {
  validate(settings);
  if (settings.local_light.has_value() != (local_maps != nullptr))
    throw InputError("render_coherent: a local light needs its cube maps, and cube maps their light");
  // The local light's rectangle, radiance, far and mesh area (14 floats), its grid, mesh points
  // (position and normal, a float4 each) and maps; one unused element each without one (OpenCL
  // has no empty buffers).
  std::vector<float> local_params(14, 0.0f), local_points(8, 0.0f);
  cl_int4 local_dims{{1, 1, 1, 1}};
  int local_kind = 0;  // 0 none, 1 rectangle, 2 mesh
  std::vector<uint32_t> local_offsets{0, 1}, local_last{0}, local_positions{0};
  std::vector<uint16_t> local_depth{0};
  if (local_maps) {
    const coherent::LocalLight& l = settings.local_light->light;
    coherent::validate(l);
    const coherent::CompressedStack& c = *local_maps;
    if (c.layout.views_theta != 6 || c.layout.views_phi != l.count() || c.offsets.size() != c.layout.texels() + 1 ||
        c.offsets.back() != c.last.size() || c.depth.size() != c.last.size())
      throw InputError("render_coherent: the local light's maps are not 6 faces of its sampling points");
    const Vec3 v[4] = {l.corner, l.edge_a, l.edge_b, settings.local_light->radiance};
    for (int k = 0; k < 4; ++k)
      for (int axis = 0; axis < 3; ++axis) local_params[3 * k + axis] = float(v[k][axis]);
    local_params[12] = float(l.far);
    local_params[13] = float(l.area);
    local_dims = {{l.samples_a, l.samples_b, c.layout.resolution, l.count()}};
    local_kind = l.is_mesh() ? 2 : 1;
    if (l.is_mesh()) {
      local_points.assign(8 * l.points.size(), 0.0f);
      for (size_t k = 0; k < l.points.size(); ++k)
        for (int axis = 0; axis < 3; ++axis) {
          local_points[8 * k + axis] = float(l.points[k][axis]);
          local_points[8 * k + 4 + axis] = float(l.normals[k][axis]);
        }
    }
    local_offsets = c.offsets;
    local_last = c.last;
    local_depth = c.depth;
    local_positions = coherent::light_positions(l);
  }
  if (objects.empty() || objects.size() > size_t(kMaxObjects))
    throw InputError("render_coherent: 1 to " + std::to_string(kMaxObjects) + " objects, got " +
                     std::to_string(objects.size()));
  // The objects' maps concatenated (each object's offsets index its own segments: the kernel
  // adds the bases to the array pointers), with their layouts and world-to-object rows.
  std::vector<uint32_t> offsets, last, positions;
  std::vector<uint16_t> depth;
  std::vector<coherent::DeviceLayout> layouts;
  std::vector<float> rows;
  std::vector<cl_uint4> bases;
  for (const PlacedStack& o : objects) {
    const coherent::CompressedStack& c = *o.stack;
    coherent::validate(c.layout);
    if (c.offsets.size() != c.layout.texels() + 1 || c.offsets.back() != c.last.size() ||
        c.depth.size() != c.last.size())
      throw InputError("render_coherent: an object's offsets, last and depth do not hold one stack");
    if (offsets.size() + c.offsets.size() > 0xffffffffu || last.size() + c.last.size() > 0xffffffffu)
      throw InputError("render_coherent: the objects' maps exceed 32-bit indices together");
    bases.push_back({{cl_uint(offsets.size()), cl_uint(last.size()), cl_uint(positions.size()), 0u}});
    offsets.insert(offsets.end(), c.offsets.begin(), c.offsets.end());
    last.insert(last.end(), c.last.begin(), c.last.end());
    depth.insert(depth.end(), c.depth.begin(), c.depth.end());
    const std::vector<uint32_t> seq = coherent::sequence_positions(c.layout);
    positions.insert(positions.end(), seq.begin(), seq.end());
    layouts.push_back(coherent::device_layout(c.layout));
    const ObjectRows r = object_rows(o.transform);
    rows.insert(rows.end(), r.begin(), r.end());
  }
  const cl::Context& ctx = rt.context();
  auto upload = [&](const void* data, size_t bytes) {
    // A zero-size buffer is invalid in OpenCL: empty inputs get one unused element.
    static const uint32_t zero[4] = {0, 0, 0, 0};
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes ? bytes : sizeof(zero),
                      const_cast<void*>(bytes ? data : zero));
  };
  auto bytes_of = [](const auto& v) { return v.size() * sizeof(v[0]); };
  const size_t n = g.pixels();
  // Named: a kernel argument does not keep its buffer alive.
  cl::Buffer layouts_buf = upload(layouts.data(), bytes_of(layouts)), rows_buf = upload(rows.data(), bytes_of(rows)),
             bases_buf = upload(bases.data(), bytes_of(bases)), offsets_buf = upload(offsets.data(), bytes_of(offsets)),
             last_buf = upload(last.data(), bytes_of(last)), depth_buf = upload(depth.data(), bytes_of(depth)),
             positions_buf = upload(positions.data(), bytes_of(positions));
  cl::Buffer local_points_buf = upload(local_points.data(), bytes_of(local_points));
  cl::Buffer local_params_buf = upload(local_params.data(), bytes_of(local_params)),
             local_offsets_buf = upload(local_offsets.data(), bytes_of(local_offsets)),
             local_last_buf = upload(local_last.data(), bytes_of(local_last)),
             local_depth_buf = upload(local_depth.data(), bytes_of(local_depth)),
             local_positions_buf = upload(local_positions.data(), bytes_of(local_positions));
  cl::Buffer pos = upload(g.position.data(), bytes_of(g.position));
  cl::Buffer nor = upload(g.normal.data(), bytes_of(g.normal));
  cl::Buffer alb = upload(g.albedo.data(), bytes_of(g.albedo));
  std::vector<float> rgb4(size_t(env.width) * env.height * 4, 0.0f);
  for (size_t t = 0; t < size_t(env.width) * env.height; ++t)
    for (int c = 0; c < 3; ++c) rgb4[4 * t + c] = env.rgb[3 * t + c];
  cl::Buffer env_rgb = upload(rgb4.data(), bytes_of(rgb4));
  cl::Buffer env_marg = upload(env.marginal.data(), bytes_of(env.marginal));
  cl::Buffer env_cond = upload(env.conditional.data(), bytes_of(env.conditional));
  cl::Buffer env_cos = upload(env.row_cos.data(), bytes_of(env.row_cos));
  cl::Buffer env_sa = upload(env.texel_solid_angle.data(), bytes_of(env.texel_solid_angle));
  std::vector<float> lights;
  for (const AreaLight& l : settings.lights)
    for (const Vec3& v : {l.corner, l.edge_a, l.edge_b, Vec3{l.radiance[0], l.radiance[1], l.radiance[2]}})
      lights.insert(lights.end(), {float(v.x), float(v.y), float(v.z), 0.0f});
  cl::Buffer light_buf = upload(lights.data(), bytes_of(lights));
  cl::Buffer out(ctx, CL_MEM_READ_WRITE, std::max<size_t>(n, 1) * 4 * sizeof(float));  // passes > 0 read it

  cl::Kernel k(rt.program({"coherent/query.clh", "coherent/render.cl"}, "-cl-std=CL1.2"), "sf_coherent_render");
  const uint32_t S = uint32_t(settings.samples);
  int a = 0;
  k.setArg(a++, cl_int(n));
  k.setArg(a++, pos);
  k.setArg(a++, nor);
  k.setArg(a++, alb);
  k.setArg(a++, cl_int(objects.size()));
  for (const cl::Buffer* b : {&layouts_buf, &rows_buf, &bases_buf, &offsets_buf, &last_buf, &depth_buf, &positions_buf})
    k.setArg(a++, *b);
  k.setArg(a++, cl_int(env.width));
  k.setArg(a++, cl_int(env.height));
  k.setArg(a++, cl_int(env.sampled ? 1 : 0));
  k.setArg(a++, env_rgb);
  k.setArg(a++, env_marg);
  k.setArg(a++, env_cond);
  k.setArg(a++, env_cos);
  k.setArg(a++, env_sa);
  k.setArg(a++, cl_int(settings.lights.size()));
  k.setArg(a++, light_buf);
  k.setArg(a++, cl_int(local_kind));
  k.setArg(a++, local_params_buf);
  k.setArg(a++, local_dims);
  k.setArg(a++, local_points_buf);
  for (const cl::Buffer* b : {&local_offsets_buf, &local_last_buf, &local_depth_buf, &local_positions_buf})
    k.setArg(a++, *b);
  k.setArg(a++, cl_uint(S));
  k.setArg(a++, cl_float(1.0f / float(S)));
  k.setArg(a++, cl_uint(sample_stride(S)));
  const int seed_arg = a;  // set per pass
  k.setArg(a++, cl_uint(settings.seed));
  k.setArg(a++, cl_int(settings.filter));
  k.setArg(a++, cl_float4{{g.eye[0], g.eye[1], g.eye[2], 0.0f}});
  k.setArg(a++, cl_float4{{settings.specular[0], settings.specular[1], settings.specular[2], settings.shininess}});
  const int pass_arg = a;
  k.setArg(a++, cl_uint(0));
  k.setArg(a++, out);
  // A multiple of the work-group size: the kernel skips the items past n.
  constexpr size_t kGroup = 64;
  const size_t global = std::max<size_t>(1, (n + kGroup - 1) / kGroup) * kGroup;
  // A launch with no pixels first: drivers that compile a kernel for its work-group size at the
  // first launch (PoCL) do it there, outside the timed render.
  k.setArg(0, cl_int(0));
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(kGroup), cl::NDRange(kGroup));
  k.setArg(0, cl_int(n));
  rt.queue().finish();
  run_passes(settings, stats, [&](int pass) {
    k.setArg(seed_arg, cl_uint(pass_seed(settings.seed, pass)));
    k.setArg(pass_arg, cl_uint(pass));
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(kGroup));
    rt.queue().finish();
  });
  std::vector<float> px(n * 4);
  if (n) rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, px.size() * sizeof(float), px.data());
  HostImage img(g.width, g.height, 3);
  img.channel_names = {"R", "G", "B"};
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) img.data[3 * i + c] = px[4 * i + c];
  return img;
}

double rmse_on_object(const HostImage& a, const HostImage& b, const GBuffer& mask) {
  double sum = 0.0;
  size_t count = 0;
  for (size_t i = 0; i < mask.pixels(); ++i) {
    if (mask.position[4 * i + 3] == 0.0f) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = double(a.data[3 * i + c]) - double(b.data[3 * i + c]);
      sum += d * d;
    }
    count += 3;
  }
  return count ? std::sqrt(sum / double(count)) : 0.0;
}

}  // namespace sf::scene

#include "coherent_stack.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "ray_tracer.hpp"
#include "view_raster.hpp"
#include "scene_library.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {

using coherent::DualDepthStack;
using coherent::kDepthMax;
using coherent::kNoSurface;
using coherent::StackLayout;

SceneGeometry load_coherent_object(const std::string& source) {
  SceneGeometry object;
  if (source == "sphere") {
    object.name = "sphere";
    add_sphere(object, "sphere", {0.0, 0.0, 0.0}, 1.0);
    return object;
  }
  if (source == "box") {
    object.name = "box";
    add_box(object, "box", {-1.0, -0.5, -0.75}, {1.0, 0.5, 0.75});
    return object;
  }
  // A path that names anything (a directory, a FIFO, a symlink loop too) is read as a mesh file,
  // which says what is wrong with it; a name that is neither a file nor a built-in is unknown.
  std::error_code ec;
  if (is_builtin_scene(source) || std::filesystem::exists(std::filesystem::symlink_status(source, ec))) {
    const SceneDefaults scene = is_builtin_scene(source) ? make_builtin_scene(source) : load_mesh_scene(source);
    object.name = scene.geometry.name;
    for (const TriMesh& m : scene.geometry.meshes)
      if (!m.ground) object.meshes.push_back(m);
    object.spheres = scene.geometry.spheres;
    if (object.meshes.empty() && object.spheres.empty())
      throw InputError("coherent object '" + source + "': nothing but a floor");
    return object;
  }
  throw InputError("coherent object '" + source +
                   "': no such file, and not a built-in object (sphere, box, or a scene)");
}

void fit_bounding_sphere(const SceneGeometry& object, StackLayout& layout) {
  constexpr double kBig = 1e300;
  Vec3 lo{kBig, kBig, kBig}, hi{-kBig, -kBig, -kBig};
  auto grow = [&](Vec3 p, double r) {
    lo = {std::min(lo.x, p.x - r), std::min(lo.y, p.y - r), std::min(lo.z, p.z - r)};
    hi = {std::max(hi.x, p.x + r), std::max(hi.y, p.y + r), std::max(hi.z, p.z + r)};
  };
  for (const TriMesh& m : object.meshes)
    for (const Vec3& v : m.vertices) grow(v, 0.0);
  for (const Sphere& s : object.spheres) grow(s.center, s.radius);
  if (!(hi.x >= lo.x)) throw InputError("coherent object '" + object.name + "' is empty");
  const Vec3 c = 0.5 * (lo + hi);
  double r = 0.0;
  for (const TriMesh& m : object.meshes)
    for (const Vec3& v : m.vertices) r = std::max(r, length(v - c));
  for (const Sphere& s : object.spheres) r = std::max(r, length(s.center - c) + s.radius);
  if (!(r > 0.0) || !std::isfinite(r)) throw InputError("coherent object '" + object.name + "' has no extent");
  layout.center = {c.x, c.y, c.z};
  layout.radius = r * (1.0 + 1e-4);
}

namespace {

// `work` on `threads` threads (<= 0: every hardware thread), this one among them; the workers
// share their items through an atomic counter of their own.
template <class Work>
void run_on_threads(int threads, const Work& work) {
  const int workers = threads > 0 ? threads : std::max(1, int(std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& th : pool) th.join();
}

// Depth t along a view's ray (from its camera plane) quantised as ViewPoint::q.
uint16_t quantise(double t, double diameter) {
  return uint16_t(std::clamp(std::nearbyint(t / diameter * kDepthMax), 0.0, double(kDepthMax)));
}

}  // namespace

ViewRange shard_views(const StackLayout& layout, size_t index, size_t count) {
  const uint64_t v = uint64_t(layout.views());
  return {uint32_t(v * index / count), uint32_t(v * (index + 1) / count)};
}

DualDepthStack render_stack(const SceneGeometry& object, const StackLayout& layout, int threads,
                            const std::function<void(size_t)>& progress, StackRenderer renderer) {
  StackPart part = render_stack_part(object, layout, {0, uint32_t(layout.views())}, threads, progress, renderer);
  DualDepthStack stack;
  stack.layout = layout;
  stack.z1 = std::move(part.z1);
  stack.z2 = std::move(part.z2);
  return stack;
}

StackPart render_stack_part(const SceneGeometry& object, const StackLayout& layout, ViewRange range, int threads,
                            const std::function<void(size_t)>& progress, StackRenderer renderer) {
  coherent::validate(layout);
  if (range.first > range.end || range.end > uint32_t(layout.views()))
    throw InputError("views " + std::to_string(range.first) + ".." + std::to_string(range.end) + " of a stack of " +
                     std::to_string(layout.views()));
  const std::vector<uint32_t> sequence = coherent::enumerate_views(layout);
  const int m = layout.resolution;
  const size_t texels = layout.texels();
  const double radius = layout.radius, diameter = 2.0 * radius;
  const int hits = layout.depth_pair == coherent::DepthPair::FirstThird ? 3 : 2;
  const Vec3 center{layout.center[0], layout.center[1], layout.center[2]};
  // A later hit starts this far past the earlier one: far below a depth step (diameter / 65534).
  const double gap = diameter * 1e-7;

  StackPart stack;
  stack.range = range;
  stack.z1.assign(size_t(range.count()) * texels, kNoSurface);
  stack.z2.assign(size_t(range.count()) * texels, kNoSurface);

  // Meshes are rasterised (the same depths at texel centres, many times faster for thousands of
  // views); analytic spheres need Embree's ray casts.
  const ViewRasterizer rasterizer(object);
  const bool rasterise = !rasterizer.has_spheres() && renderer != StackRenderer::Embree;
  std::unique_ptr<RayTracer> tracer = rasterise ? nullptr : std::make_unique<RayTracer>(object);

  std::atomic<size_t> next{range.first};
  auto work = [&]() {
    std::vector<Ray> rays(static_cast<size_t>(m));
    std::vector<double> t(texels * size_t(hits));
    for (size_t i = next++; i < range.end; i = next++) {
      const coherent::ViewFrame f = coherent::view_frame(layout, sequence[i]);
      const Vec3 dir{f.dir[0], f.dir[1], f.dir[2]}, right{f.right[0], f.right[1], f.right[2]},
          up{f.up[0], f.up[1], f.up[2]};
      if (rasterise) {
        rasterizer.render({center, dir, right, up, radius, radius, m}, hits, gap, t);
      } else {
        for (int y = 0; y < m; ++y) {
          const double b = ((y + 0.5) / m - 0.5) * diameter;
          for (int x = 0; x < m; ++x) {
            const double a = ((x + 0.5) / m - 0.5) * diameter;
            rays[size_t(x)] = {center + radius * dir + a * right + b * up, -dir};
          }
          tracer->hits_along(rays.data(), size_t(m), hits, gap, t.data() + size_t(y) * size_t(m) * size_t(hits));
        }
      }
      uint16_t* z1 = stack.z1.data() + (i - range.first) * texels;
      uint16_t* z2 = stack.z2.data() + (i - range.first) * texels;
      for (int y = 0; y < m; ++y) {
        for (int x = 0; x < m; ++x) {
          const size_t at = size_t(y) * m + size_t(x);
          const double* h = t.data() + at * hits;
          if (!std::isfinite(h[0])) continue;  // a miss: kNoSurface twice, lit for every query
          const uint16_t first = quantise(h[0], diameter);
          uint32_t second = kNoSurface;
          if (std::isfinite(h[hits - 1])) {
            second = quantise(h[hits - 1], diameter);
          } else if (layout.far_plane == coherent::FarPlane::Sphere) {
            // The ray leaves the bounding sphere at t = R + sqrt(R^2 - r^2), r its distance from
            // the centre's line (sec. 3.1, "spherical far plane").
            const double a = ((x + 0.5) / m - 0.5) * diameter, b = ((y + 0.5) / m - 0.5) * diameter;
            second = quantise(radius + std::sqrt(std::max(0.0, radius * radius - a * a - b * b)), diameter);
          }
          // A pair thinner than one depth step still separates: z2 = z1 + 1.
          z1[at] = first;
          z2[at] = uint16_t(std::max<uint32_t>(second, uint32_t(first) + 1));
        }
      }
      if (progress) progress(1);
    }
  };
  run_on_threads(threads, work);
  return stack;
}

coherent::LocalLight mesh_light(const TriMesh& mesh, int count) {
  if (count < 1 || count > coherent::kMaxLightSamples)
    throw InputError("mesh light: 1 to " + std::to_string(coherent::kMaxLightSamples) + " sampling points, got " +
                     std::to_string(count));
  std::vector<double> cdf{0.0};
  std::vector<size_t> tris;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
    const double area = 0.5 * length(cross(b - a, c - a));
    if (!(area > 0.0)) continue;  // degenerate: emits nothing
    cdf.push_back(cdf.back() + area);
    tris.push_back(t);
  }
  if (tris.empty()) throw InputError("mesh light '" + mesh.name + "' has no area");
  coherent::LocalLight l;
  l.area = cdf.back();
  std::vector<std::pair<Vec3, Vec3>> samples;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (int k = 0; k < count; ++k) {
    const double target = (k + 0.5) / count * l.area;
    const size_t i =
        std::min(tris.size() - 1, size_t(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin()) - 1);
    const auto& tri = mesh.triangles[tris[i]];
    const Vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
    const double r1 = std::clamp((target - cdf[i]) / (cdf[i + 1] - cdf[i]), 0.0, 1.0);
    const double g = k * 0.6180339887498949;
    const double r2 = g - std::floor(g);
    const double s = std::sqrt(r1);
    const Vec3 p = (1.0 - s) * a + (s * (1.0 - r2)) * b + (s * r2) * c;
    samples.push_back({p, normalize(cross(b - a, c - a))});
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = std::min(lo[axis], p[axis]);
      hi[axis] = std::max(hi[axis], p[axis]);
    }
  }
  auto cell = [&](const Vec3& p, int axis) {
    const double span = hi[axis] - lo[axis];
    return uint32_t(span > 0.0 ? std::clamp((p[axis] - lo[axis]) / span * 1023.0, 0.0, 1023.0) : 0.0);
  };
  std::stable_sort(samples.begin(), samples.end(), [&](const auto& x, const auto& y) {
    return morton(cell(x.first, 0), cell(x.first, 1), cell(x.first, 2)) <
           morton(cell(y.first, 0), cell(y.first, 1), cell(y.first, 2));
  });
  for (const auto& [p, n] : samples) {
    l.points.push_back(p);
    l.normals.push_back(n);
  }
  l.samples_a = count;
  l.samples_b = 1;
  l.ordering = coherent::Ordering::ScanLine;
  return l;
}

coherent::StackLayout fit_local_light(const SceneGeometry& object, coherent::LocalLight& light, int resolution) {
  coherent::StackLayout sphere;
  fit_bounding_sphere(object, sphere);
  const Vec3 center{sphere.center[0], sphere.center[1], sphere.center[2]};
  light.far = coherent::light_far(light, center, sphere.radius);
  return coherent::cube_layout(light, resolution, center, sphere.radius);
}

StackPart render_cube_stack_part(const SceneGeometry& object, const coherent::LocalLight& light,
                                 const coherent::StackLayout& layout, ViewRange range, int threads,
                                 const std::function<void(size_t)>& progress) {
  coherent::validate(light);
  coherent::validate(layout);
  const size_t n = size_t(light.count());
  if (layout.views_theta != 6 || size_t(layout.views_phi) != n || range.first > range.end ||
      range.end > uint32_t(6 * n))
    throw InputError("cube maps " + std::to_string(range.first) + ".." + std::to_string(range.end) +
                     " of a local light's stack of " + std::to_string(6 * n));
  const std::vector<uint32_t> grid = coherent::light_sequence(light);
  const size_t texels = layout.texels();
  const int m = layout.resolution;
  const double gap = 2.0 * layout.radius * 1e-7;  // as render_stack_part: far below a depth step
  StackPart part;
  part.range = range;
  part.z1.assign(size_t(range.count()) * texels, kNoSurface);
  part.z2.assign(size_t(range.count()) * texels, kNoSurface);
  const RayTracer tracer(object);
  std::atomic<size_t> next{range.first};
  auto work = [&]() {
    std::vector<Ray> rays(static_cast<size_t>(m));
    std::vector<double> inv_length(static_cast<size_t>(m));
    std::vector<double> t(static_cast<size_t>(m) * 2);
    for (size_t map = next++; map < range.end; map = next++) {
      const int k = int(map / n);
      const Vec3 s = light.sample_point(grid[map % n]);
      const coherent::CubeFace f = coherent::cube_face(k);
      uint16_t* z1 = part.z1.data() + (map - range.first) * texels;
      uint16_t* z2 = part.z2.data() + (map - range.first) * texels;
      for (int y = 0; y < m; ++y) {
        const double b = (y + 0.5) * 2.0 / m - 1.0;
        for (int x = 0; x < m; ++x) {
          const double a = (x + 0.5) * 2.0 / m - 1.0;
          const Vec3 d = f.n + a * f.u + b * f.v;
          const double len = length(d);
          inv_length[size_t(x)] = 1.0 / len;
          rays[size_t(x)] = {s, (1.0 / len) * d};
        }
        tracer.hits_along(rays.data(), size_t(m), 2, gap, t.data());
        for (int x = 0; x < m; ++x) {
          const double* h = t.data() + size_t(x) * 2;
          if (!std::isfinite(h[0])) continue;  // a miss: lit for every query
          // Planar depth: the distance along the ray times the cosine to the face's axis.
          auto q = [&](double dist) {
            return uint32_t(std::clamp(std::nearbyint(dist * inv_length[size_t(x)] / light.far * kDepthMax), 0.0,
                                       double(kDepthMax)));
          };
          const uint32_t first = q(h[0]);
          const uint32_t second = std::isfinite(h[1]) ? q(h[1]) : kNoSurface;
          const size_t at = size_t(y) * m + size_t(x);
          z1[at] = uint16_t(first);
          z2[at] = uint16_t(std::max<uint32_t>(second, first + 1));
        }
      }
      if (progress) progress(1);
    }
  };
  run_on_threads(threads, work);
  return part;
}

coherent::DualDepthStack render_cube_stack(const SceneGeometry& object, coherent::LocalLight& light, int resolution,
                                           int threads, const std::function<void(size_t)>& progress) {
  const coherent::StackLayout layout = fit_local_light(object, light, resolution);
  StackPart part = render_cube_stack_part(object, light, layout, {0, uint32_t(layout.views())}, threads, progress);
  coherent::DualDepthStack stack;
  stack.layout = layout;
  stack.z1 = std::move(part.z1);
  stack.z2 = std::move(part.z2);
  return stack;
}

}  // namespace sf::scene

// Layers, views and camera paths of the scene generator (layer_render.hpp).
#include "layer_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "row_workers.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxFrames = 1000;

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Vec3 camera_axis(const PerspectiveCamera& camera) { return normalize(camera.target - camera.position); }

}  // namespace

std::vector<sf::WorldBox> geometry_boxes(const SceneGeometry& geometry) {
  std::vector<sf::WorldBox> boxes;
  boxes.reserve(geometry.triangle_count() + geometry.spheres.size());
  for (const TriMesh& mesh : geometry.meshes)
    for (const auto& tri : mesh.triangles) {
      sf::WorldBox box;
      for (int axis = 0; axis < 3; ++axis) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (uint32_t index : tri) {
          const double c = component(mesh.vertices[index], axis);
          lo = std::min(lo, c);
          hi = std::max(hi, c);
        }
        box.lo[axis] = lo;
        box.hi[axis] = hi;
      }
      boxes.push_back(box);
    }
  for (const Sphere& s : geometry.spheres)
    boxes.push_back({{s.center.x - s.radius, s.center.y - s.radius, s.center.z - s.radius},
                     {s.center.x + s.radius, s.center.y + s.radius, s.center.z + s.radius}});
  return boxes;
}

sf::CameraFrustum camera_frustum(const PerspectiveCamera& camera, double near_depth, double far_depth) {
  // The axes of PerspectiveCamera::ray_through: right = forward x up_hint, up = right x forward.
  const Vec3 forward = camera_axis(camera);
  const Vec3 right = normalize(cross(forward, camera.up_hint));
  const Vec3 up = cross(right, forward);
  sf::CameraFrustum f;
  f.position = to_point(camera.position);
  f.forward = to_point(forward);
  f.up = to_point(up);
  f.vertical_fov_degrees = camera.vertical_fov_degrees;
  f.aspect = double(camera.width) / double(camera.height);
  f.near_depth = near_depth;
  f.far_depth = far_depth;
  return f;
}

ViewDepths default_view_depths(const PerspectiveCamera& camera, const SceneGeometry& geometry) {
  const Interval x = project_onto(geometry, {1, 0, 0});
  const Interval y = project_onto(geometry, {0, 1, 0});
  const Interval z = project_onto(geometry, {0, 0, 1});
  const Vec3 forward = camera_axis(camera);
  double deepest = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner{(k & 1) ? x.hi : x.lo, (k & 2) ? y.hi : y.lo, (k & 4) ? z.hi : z.lo};
    deepest = std::max(deepest, dot(corner - camera.position, forward));
  }
  if (!(deepest > 0.0) || !std::isfinite(deepest))
    throw InputError("the scene lies behind the camera (move --camera-pos or --camera-look)");
  ViewDepths depths;
  depths.far_depth = 1.01 * deepest;
  const Vec3 p = camera.position;
  const Vec3 nearest{std::clamp(p.x, x.lo, x.hi), std::clamp(p.y, y.lo, y.hi), std::clamp(p.z, z.lo, z.hi)};
  const double tan_half = std::tan(0.5 * camera.vertical_fov_degrees * kPi / 180.0);
  const double aspect = double(camera.width) / double(camera.height);
  const double cos_diagonal = 1.0 / std::sqrt(1.0 + tan_half * tan_half * (1.0 + aspect * aspect));
  depths.near_depth = std::max(length(nearest - p) * cos_diagonal, 1e-3 * depths.far_depth);
  if (!(depths.near_depth < depths.far_depth)) depths.near_depth = 1e-3 * depths.far_depth;
  return depths;
}

std::vector<HostImage> render_layers(const RayTracer& tracer, const sf::CascadeSet& set, int threads, bool progress) {
  std::vector<HostImage> maps;
  for (size_t k = 0; k < set.layers.size(); ++k) {
    const sf::LayerTransform& transform = set.layers[k].transform;
    HostImage map(set.width, set.height, 1, 1.0f);
    map.channel_names = {"Z"};
    const std::string label = "layer " + std::to_string(k);
    for_each_row(label.c_str(), set.height, set.width, threads, progress, [&](int j) {
      std::vector<Ray> rays(size_t(set.width));
      std::vector<char> valid(size_t(set.width), 0);
      for (int i = 0; i < set.width; ++i) {
        sf::Point3 origin, direction;
        double depth_per_length = 0.0;
        const double u = (i + 0.5) / set.width, v = (j + 0.5) / set.height;
        if (!transform.ray(u, v, origin, direction, depth_per_length)) continue;
        rays[i] = Ray{{origin[0], origin[1], origin[2]}, {direction[0], direction[1], direction[2]}};
        valid[i] = 1;
      }
      std::vector<double> t(size_t(set.width));
      tracer.hits_along(rays.data(), rays.size(), 1, 0.0, t.data());
      for (int i = 0; i < set.width; ++i) {
        if (!valid[i] || !std::isfinite(t[i])) continue;  // no ray (singular) or nothing hit: 1
        const double d = transform.apply(to_point(rays[i].at(t[i]))).d;
        map.at(i, j) = float(std::clamp(d, 0.0, 1.0));
      }
    });
    maps.push_back(std::move(map));
  }
  return maps;
}

sf::ViewReceivers view_receivers(const HostImage& view) {
  if (view.channels != 11) throw InputError("a view image has 11 channels (io::view_channel_names())");
  sf::ViewReceivers v;
  v.width = view.width;
  v.height = view.height;
  std::vector<float>* arrays[11] = {&v.x, &v.y, &v.z, &v.depth, &v.dxx, &v.dxy, &v.dxz, &v.dyx, &v.dyy, &v.dyz, &v.ndl};
  for (auto* a : arrays) a->resize(view.texels());
  for (size_t t = 0; t < view.texels(); ++t)
    for (int c = 0; c < 11; ++c) (*arrays[c])[t] = view.data[t * 11 + c];
  return v;
}

Vec3 ground_ahead(const PerspectiveCamera& camera) {
  const Vec3 axis = normalize(camera.target - camera.position);
  const Vec3 ahead{axis.x, 0.0, axis.z};
  return length(ahead) > 1e-9 ? normalize(ahead) : axis;
}

std::vector<PerspectiveCamera> camera_path(const PerspectiveCamera& start, const CameraPathOptions& options,
                                           double far_depth) {
  if (options.frames < 1 || options.frames > kMaxFrames)
    throw InputError("--frames must lie in 1.." + std::to_string(kMaxFrames) + ", got " +
                     std::to_string(options.frames));
  if (options.walk_to && !finite(*options.walk_to)) throw InputError("--camera-to must be three finite numbers");
  if (!std::isfinite(options.orbit_degrees)) throw InputError("--orbit-degrees must be a finite number");
  std::vector<PerspectiveCamera> cameras;
  const Vec3 look = start.target - start.position;
  Vec3 walk_to = start.position;
  if (options.kind == CameraPathKind::Walk) {
    if (options.walk_to) {
      walk_to = *options.walk_to;
    } else {
      walk_to = start.position + (0.1 * far_depth) * ground_ahead(start);
    }
  }
  for (int i = 0; i < options.frames; ++i) {
    const double s = options.frames > 1 ? double(i) / double(options.frames - 1) : 0.0;
    PerspectiveCamera camera = start;
    if (options.kind == CameraPathKind::Walk) {
      camera.position = start.position + s * (walk_to - start.position);
      camera.target = camera.position + look;
    } else {
      // Right-handed about +y through the target: counter-clockwise seen from above.
      const double a = s * options.orbit_degrees * kPi / 180.0;
      const Vec3 r = start.position - start.target;
      camera.position =
          start.target + Vec3{r.x * std::cos(a) + r.z * std::sin(a), r.y, -r.x * std::sin(a) + r.z * std::cos(a)};
    }
    cameras.push_back(camera);
  }
  return cameras;
}

// Positions within +-1e7 units and a field of view of at least 0.01 degrees: past them the ray
// tracer's single-precision rays lose their direction (Embree stops on an assertion).
void validate_camera(const PerspectiveCamera& camera, double near_depth, double far_depth) {
  constexpr double kMaxCoordinate = 1e7;
  const auto within = [](const Vec3& p) {
    return finite(p) && std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate &&
           std::abs(p.z) <= kMaxCoordinate;
  };
  if (!within(camera.position)) throw InputError("--camera-pos must be three numbers within +-1e7");
  if (!within(camera.target)) throw InputError("--camera-look must be three numbers within +-1e7");
  if (!(length(camera.target - camera.position) > 0.0)) throw InputError("--camera-look must differ from --camera-pos");
  if (!(length(cross(normalize(camera.target - camera.position), normalize(camera.up_hint))) > 1e-6))
    throw InputError("--camera-look must not lie straight above or below --camera-pos (no image up direction)");
  if (!(camera.vertical_fov_degrees >= 0.01 && camera.vertical_fov_degrees < 170.0))
    throw InputError("--camera-fov must lie in [0.01, 170) degrees");
  if (!std::isfinite(near_depth) || !std::isfinite(far_depth) || !(near_depth > 0.0) || !(far_depth > near_depth))
    throw InputError("--camera-near and --camera-far must be finite with 0 < near < far (got " +
                     std::to_string(near_depth) + ", " + std::to_string(far_depth) + ")");
}

}  // namespace sf::scene

#include "scene_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

namespace sf::scene {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Shadow rays start this far (relative to the light depth range) off the surface.
constexpr double kShadowRayOffset = 1e-4;

// Calls row_fn(y) for every y in [0, rows), rows interleaved over the hardware threads.
template <class RowFn>
void for_each_row(int rows, const RowFn& row_fn) {
  const int workers = std::max(1, std::min(rows, static_cast<int>(std::thread::hardware_concurrency())));
  std::vector<std::thread> threads;
  threads.reserve(workers);
  for (int w = 0; w < workers; ++w) {
    threads.emplace_back([w, workers, rows, &row_fn] {
      for (int y = w; y < rows; y += workers) row_fn(y);
    });
  }
  for (std::thread& t : threads) t.join();
}

HostImage render_light_depth(const SceneSetup& setup, SurfaceSet surfaces, float miss_value) {
  HostImage image(setup.map_width, setup.map_height, 1);
  image.channel_names = {"Z"};
  const double range = setup.light.depth_range();
  for_each_row(image.height, [&](int j) {
    for (int i = 0; i < image.width; ++i) {
      const Ray ray = setup.light.texel_ray(i, j, image.width, image.height);
      const std::optional<Hit> hit = closest_hit(ray, setup.geometry, surfaces);
      image.at(i, j) = hit ? static_cast<float>(hit->t / range) : miss_value;
    }
  });
  return image;
}

std::optional<Hit> camera_hit(const SceneSetup& setup, int x, int y) {
  return closest_hit(setup.camera.ray_through(x + 0.5, y + 0.5), setup.geometry, SurfaceSet::All);
}

// Light coordinates of the point where the camera ray through image point (x, y) meets the
// plane through `point` with normal `normal`; nothing when the ray runs parallel to the plane
// or meets it behind the camera.
std::optional<LightCoords> light_coords_on_plane(const SceneSetup& setup, double x, double y,
                                                 Vec3 point, Vec3 normal) {
  const Ray ray = setup.camera.ray_through(x, y);
  const double denominator = dot(normal, ray.direction);
  if (std::abs(denominator) < 1e-12) return std::nullopt;
  const double t = dot(normal, point - ray.origin) / denominator;
  if (!(t > 0.0)) return std::nullopt;
  return setup.light.project(ray.at(t));
}

// Footprint of pixel (x, y) in level-0 shadow-map texels. Method: the rays through the midpoints
// of the pixel's left/right edges and of its top/bottom edges are intersected with the tangent
// plane of the hit surface at the pixel-centre hit; each pair's distance in shadow-map texels
// (du*W, dv*H) is a footprint width, f = the larger of the two. Being per pixel, this needs no
// neighbours (no special cases at image edges or object silhouettes). At grazing angles where an
// edge ray misses the plane, f is capped at the shadow-map size.
double footprint_texels(const SceneSetup& setup, int x, int y, const Hit& hit) {
  const double cap = std::max(setup.map_width, setup.map_height);
  const Vec3 point = setup.camera.ray_through(x + 0.5, y + 0.5).at(hit.t);
  auto width_between = [&](double x0, double y0, double x1, double y1) {
    const auto a = light_coords_on_plane(setup, x0, y0, point, hit.normal);
    const auto b = light_coords_on_plane(setup, x1, y1, point, hit.normal);
    if (!a || !b) return cap;
    return std::hypot((a->u - b->u) * setup.map_width, (a->v - b->v) * setup.map_height);
  };
  const double across = width_between(x, y + 0.5, x + 1.0, y + 0.5);
  const double down = width_between(x + 0.5, y, x + 0.5, y + 1.0);
  return std::min(cap, std::max(across, down));
}

bool lit_by_light(const SceneSetup& setup, Vec3 point, Vec3 normal) {
  const Vec3 towards_light = -setup.light.forward;
  if (dot(normal, towards_light) <= 0.0) return false;  // faces away from the light
  const double offset = kShadowRayOffset * setup.light.depth_range();
  const Ray shadow_ray{point + offset * normal, towards_light};
  return !any_hit(shadow_ray, setup.geometry);
}

}  // namespace

HostImage render_shadow_map(const SceneSetup& setup) {
  return render_light_depth(setup, SurfaceSet::All, 1.0f);
}

HostImage render_receiver_depth(const SceneSetup& setup) {
  return render_light_depth(setup, SurfaceSet::FloorOnly, kNaN);
}

HostImage render_receivers(const SceneSetup& setup) {
  HostImage image(setup.camera.width, setup.camera.height, 4, kNaN);
  image.channel_names = {"u", "v", "d", "f"};
  image.channel_formats = {"float", "float", "float", "half"};
  for_each_row(image.height, [&](int y) {
    for (int x = 0; x < image.width; ++x) {
      const std::optional<Hit> hit = camera_hit(setup, x, y);
      if (!hit) continue;
      const Vec3 point = setup.camera.ray_through(x + 0.5, y + 0.5).at(hit->t);
      const LightCoords coords = setup.light.project(point);
      image.at(x, y, 0) = static_cast<float>(coords.u);
      image.at(x, y, 1) = static_cast<float>(coords.v);
      image.at(x, y, 2) = static_cast<float>(coords.d);
      image.at(x, y, 3) = static_cast<float>(footprint_texels(setup, x, y, *hit));
    }
  });
  return image;
}

HostImage render_reference_hard(const SceneSetup& setup) {
  HostImage image(setup.camera.width, setup.camera.height, 1, 1.0f);
  image.channel_names = {"Y"};
  for_each_row(image.height, [&](int y) {
    for (int x = 0; x < image.width; ++x) {
      const std::optional<Hit> hit = camera_hit(setup, x, y);
      if (!hit) continue;
      const Vec3 point = setup.camera.ray_through(x + 0.5, y + 0.5).at(hit->t);
      image.at(x, y) = lit_by_light(setup, point, hit->normal) ? 1.0f : 0.0f;
    }
  });
  return image;
}

double min_occluder_floor_gap(const HostImage& shadow_map, const HostImage& receiver_depth) {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < shadow_map.data.size(); ++k) {
    const float floor_depth = receiver_depth.data[k];
    const float first_depth = shadow_map.data[k];
    if (std::isfinite(floor_depth) && first_depth < floor_depth) {
      gap = std::min(gap, static_cast<double>(floor_depth) - first_depth);
    }
  }
  return gap;
}

}  // namespace sf::scene

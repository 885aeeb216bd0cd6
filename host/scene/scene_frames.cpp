// Cameras, view depths and layouts of the frames of a generated scene (scene_frames.hpp).
#include "scene_frames.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "scene_library.hpp"
#include "scene_render.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::scene {
namespace {

std::optional<sf::LayoutOptions> layout_options(const LayoutRequest& r, int map_size) {
  if (r.layout.empty()) {
    if (r.cascades || r.split_lambda || r.tsm_focus || r.blend || r.no_stabilize)
      throw InputError(
          "--cascades, --split-lambda, --tsm-focus, --cascade-blend and --no-stabilize need --layout "
          "single|pssm|tsm|pssm+tsm");
    return std::nullopt;
  }
  sf::LayoutOptions o;
  o.kind = sf::parse_layout(r.layout);
  o.map_size = map_size;
  if (r.cascades) {
    if (*r.cascades < 1 || *r.cascades > sf::kMaxCascadeLayers)
      throw InputError("--cascades must lie in 1.." + std::to_string(sf::kMaxCascadeLayers) + ", got " +
                       std::to_string(*r.cascades));
    o.cascades = *r.cascades;
  }
  if (r.split_lambda) {
    if (!(*r.split_lambda >= 0.0 && *r.split_lambda <= 1.0)) throw InputError("--split-lambda must lie in [0, 1]");
    o.split_lambda = *r.split_lambda;
  }
  if (r.tsm_focus) {
    if (!(*r.tsm_focus >= 0.0 && *r.tsm_focus <= 1.0)) throw InputError("--tsm-focus must lie in [0, 1]");
    o.tsm_focus = *r.tsm_focus;
  }
  if (r.blend) {
    if (!(*r.blend >= 0.0 && *r.blend < 1.0)) throw InputError("--cascade-blend must lie in [0, 1)");
    o.blend = *r.blend;
  }
  o.stabilize = !r.no_stabilize;
  return o;
}

CameraPathOptions path_options(const CameraRequest& r) {
  CameraPathOptions p;
  p.frames = r.frames;
  if (r.path == "walk") {
    p.kind = CameraPathKind::Walk;
    if (r.orbit_degrees) throw InputError("--orbit-degrees needs --camera-path orbit");
  } else if (r.path == "orbit") {
    p.kind = CameraPathKind::Orbit;
    if (r.walk_to) throw InputError("--camera-to needs --camera-path walk");
  } else {
    throw InputError("--camera-path must be walk or orbit, got '" + r.path + "'");
  }
  p.walk_to = r.walk_to;
  if (r.orbit_degrees) p.orbit_degrees = *r.orbit_degrees;
  return p;
}

}  // namespace

PerspectiveCamera requested_camera(const CameraRequest& request, const PerspectiveCamera& scene_camera) {
  PerspectiveCamera camera = scene_camera;
  if (request.position) camera.position = *request.position;
  if (request.look) camera.target = *request.look;
  if (request.fov_degrees) camera.vertical_fov_degrees = *request.fov_degrees;
  return camera;
}

FramePlan plan_frames(const CameraRequest& camera, const LayoutRequest& layout, const SceneSetup& setup,
                      const SceneDefaults& defaults) {
  FramePlan plan;
  plan.path = path_options(camera);
  plan.layout = layout_options(layout, setup.map_width);
  if (plan.layout && setup.light.type != LightType::Ortho)
    throw InputError("--layout needs --light ortho (cascades are fitted for a directional light)");
  // Near/far: the options, else the scene's own, else derived from each frame's camera.
  // NaN = derived (a plain double: gcc's -Wmaybe-uninitialized misreads optionals captured here).
  constexpr double kDerived = std::numeric_limits<double>::quiet_NaN();
  const double near_depth = camera.near_depth            ? *camera.near_depth
                            : defaults.camera_near > 0.0 ? defaults.camera_near
                                                         : kDerived;
  const double far_depth = camera.far_depth            ? *camera.far_depth
                           : defaults.camera_far > 0.0 ? defaults.camera_far
                                                       : kDerived;
  validate_camera(setup.camera, 1.0, 2.0);  // its position, look and fov first; depths per frame
  const auto resolve = [&](const PerspectiveCamera& c) {
    ViewDepths d;
    if (std::isnan(near_depth) || std::isnan(far_depth)) d = default_view_depths(c, setup.geometry);
    if (!std::isnan(near_depth)) d.near_depth = near_depth;
    if (!std::isnan(far_depth)) d.far_depth = far_depth;
    return d;
  };
  const double path_far = resolve(setup.camera).far_depth;
  const std::vector<PerspectiveCamera> cameras = camera_path(setup.camera, plan.path, path_far);
  std::vector<sf::WorldBox> boxes;
  if (plan.layout) boxes = geometry_boxes(setup.geometry);
  const sf::Point3 light_direction = to_point(setup.light.forward);
  for (size_t i = 0; i < cameras.size(); ++i) {
    SceneFrame frame;
    if (cameras.size() > 1) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%03zu", i);
      frame.dir = name;
    }
    frame.camera = cameras[i];
    frame.depths = resolve(frame.camera);
    validate_camera(frame.camera, frame.depths.near_depth, frame.depths.far_depth);
    if (plan.layout)
      frame.layers =
          sf::fit_layout(*plan.layout, camera_frustum(frame.camera, frame.depths.near_depth, frame.depths.far_depth),
                         light_direction, boxes);
    plan.frames.push_back(std::move(frame));
  }
  return plan;
}

}  // namespace sf::scene

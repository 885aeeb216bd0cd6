#pragma once
// The scene side of layered shadow maps (cascades.hpp, methods.md sec. 6; Oliveira 2009): the
// geometry's bounding boxes and the camera's frustum that a layout is fitted to, the layers'
// depth maps ray-cast through their own transforms, the camera view as sf::ViewReceivers, and
// camera paths for frame sequences. Everything is deterministic and does not depend on the
// thread count (every texel and pixel is computed on its own).
#include <optional>
#include <vector>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/host_image.hpp"

#include "ray_tracer.hpp"
#include "scene_geometry.hpp"
#include "scene_views.hpp"

namespace sf::scene {

inline sf::Point3 to_point(Vec3 v) { return {v.x, v.y, v.z}; }

// One box per triangle and per sphere: the tightest boxes fit_layout can get, so each layer's
// depth range encloses only what overlaps its map.
std::vector<sf::WorldBox> geometry_boxes(const SceneGeometry& geometry);

// The frustum of a pinhole camera (its aspect from width / height) serving view depths
// [near_depth, far_depth]. No checks: fit_layout validates it.
sf::CameraFrustum camera_frustum(const PerspectiveCamera& camera, double near_depth, double far_depth);

struct ViewDepths {
  double near_depth = 0.0;
  double far_depth = 0.0;
};
// Defaults for scenes without their own (the small ones): far = the deepest corner of the
// geometry's bounding box along the camera's axis (+1%), near = the bounding box's distance from
// the camera times the cosine of the frustum's half-diagonal angle (a lower bound on the view
// depth of anything in view), at least far / 1000. InputError when the scene lies behind the
// camera.
ViewDepths default_view_depths(const PerspectiveCamera& camera, const SceneGeometry& geometry);

// Depth map of every layer of `set` (set.width x set.height, channel Z): the ray of texel centre
// (u, v) = ((i + 0.5) / W, (j + 0.5) / H) from its point of depth 0 along LayerTransform::ray;
// the stored value is transform.apply(first hit).d clamped to [0, 1], 1 where nothing is hit.
// threads <= 0: all cores; progress: a bar on stderr for layers over a second.
std::vector<HostImage> render_layers(const RayTracer& tracer, const sf::CascadeSet& set, int threads, bool progress);

// CameraImages::view as structure of arrays (background pixels all NaN, as io::load_view_receivers
// reads the file back).
sf::ViewReceivers view_receivers(const HostImage& view);

// The direction a walk takes: the camera's look direction without its vertical part (the look
// direction itself when the camera looks straight down or up), unit length.
Vec3 ground_ahead(const PerspectiveCamera& camera);

// A camera path of `frames` cameras starting with `start`:
//  Walk: a straight line from start.position to `walk_to` (default: 10% of far_depth ahead along
//        the look direction projected on the ground), the look direction kept (the target moves
//        with the camera).
//  Orbit: around start.target at constant height, by orbit_degrees in all (counter-clockwise
//        seen from above), always looking at the target.
// Frame i sits at fraction i / (frames - 1) of the way (frame 0 = start).
enum class CameraPathKind { Walk, Orbit };
struct CameraPathOptions {
  int frames = 1;  // 1..1000
  CameraPathKind kind = CameraPathKind::Walk;
  std::optional<Vec3> walk_to;
  double orbit_degrees = 30.0;
};
// Throws InputError for frames outside 1..1000, a non-finite walk_to or orbit angle.
std::vector<PerspectiveCamera> camera_path(const PerspectiveCamera& start, const CameraPathOptions& options,
                                           double far_depth);

// Checks a camera as the CLI's options name it: finite position and target, the two distinct,
// not looking straight along the up vector, vertical fov in (0, 170), 0 < near < far finite.
void validate_camera(const PerspectiveCamera& camera, double near_depth, double far_depth);

}  // namespace sf::scene

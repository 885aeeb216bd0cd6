#pragma once
// The frames of `shadowfilter scene`: the camera options (--camera-*), the camera path
// (--frames, --camera-path) and the cascade layout (--layout ...) turned into one camera, its view
// depths and its fitted cascade set per frame. All validated before anything is rendered.
#include <optional>
#include <string>
#include <vector>

#include "shadowfilter/cascades.hpp"

#include "layer_render.hpp"
#include "scene_math.hpp"
#include "scene_views.hpp"

namespace sf::scene {

struct SceneSetup;
struct SceneDefaults;

struct CameraRequest {
  std::optional<Vec3> position;  // --camera-pos
  std::optional<Vec3> look;      // --camera-look: the point looked at
  std::optional<double> fov_degrees, near_depth, far_depth;
  int frames = 1;
  std::string path = "walk";  // walk | orbit
  std::optional<Vec3> walk_to;
  std::optional<double> orbit_degrees;
};

struct LayoutRequest {
  std::string layout;  // "" = no layers; single | pssm | tsm | pssm+tsm
  std::optional<int> cascades;
  std::optional<double> split_lambda, tsm_focus, blend;
  bool no_stabilize = false;
};

struct SceneFrame {
  std::string dir;  // "" with one frame, else "frame_000", "frame_001", ...
  PerspectiveCamera camera;
  ViewDepths depths;
  std::optional<sf::CascadeSet> layers;  // with --layout
};

struct FramePlan {
  CameraPathOptions path;
  std::optional<sf::LayoutOptions> layout;
  std::vector<SceneFrame> frames;
};

// --camera-pos, --camera-look, --camera-fov over the scene's default camera.
PerspectiveCamera requested_camera(const CameraRequest& request, const PerspectiveCamera& scene_camera);

// Every frame's camera (the path from setup.camera), view depths (--camera-near/--camera-far,
// else the scene's, else default_view_depths per frame) and, with a layout, its cascade set for
// setup.light (an orthographic light only) at setup.map_width. Throws InputError naming the
// option for anything invalid.
FramePlan plan_frames(const CameraRequest& camera, const LayoutRequest& layout, const SceneSetup& setup,
                      const SceneDefaults& defaults);

}  // namespace sf::scene

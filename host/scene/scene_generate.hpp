#pragma once
// One call that turns the `shadowfilter scene` arguments into a finished scene directory.
#include <optional>
#include <string>

#include "scene_frames.hpp"
#include "scene_library.hpp"
#include "scene_render.hpp"

namespace sf::scene {

struct SceneRequest {
  std::string scene;  // built-in name or mesh file
  std::string out_dir;
  int map_size = 2048;
  std::string receivers = "1920x1080";  // WIDTHxHEIGHT
  std::string light = "ortho";          // ortho | perspective
  std::optional<Vec3> light_dir;        // ortho direction (default: the scene's)
  std::optional<Vec3> light_pos;        // perspective position (default: from the direction)
  double fov_degrees = 0.0;             // perspective; 0 = fitted to the scene
  std::optional<double> light_size;     // default: the scene's
  std::optional<double> light_height;   // a rectangular light's side along down (default: a square)
  int samples = 64;
  std::optional<bool> pixel_average;  // the soft reference over the whole pixel (default: the scene's)
  unsigned seed = 1;
  CameraRequest camera;  // --camera-*, --frames, --camera-path
  LayoutRequest layout;  // --layout and its options
  bool progress = true;
  int threads = 0;
};

struct SceneSummary {
  SceneSetup setup;
  FramePlan plan;
  double min_occluder_floor_gap = 0.0;
  double seconds = 0.0;
};

// Validates the request and builds the scene setup (no files touched). Throws InputError.
SceneSetup make_setup(const SceneRequest& request, SceneDefaults* defaults_out = nullptr);

// Renders every image and writes the directory (all at once; nothing on error): the light's
// images and scene.json in DIR, each frame's camera images (receivers, references, view) and
// layers (cascade_K.exr) in DIR with one frame, else in DIR/frame_000, DIR/frame_001, ...
SceneSummary generate_scene(const SceneRequest& request);

}  // namespace sf::scene

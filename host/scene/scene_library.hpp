#pragma once
// The built-in scenes (each one a failure case of the seeds) and real meshes placed on a
// floor. A scene comes with its own default light direction, camera and light size.
#include <string>
#include <vector>

#include "scene_geometry.hpp"
#include "scene_views.hpp"

namespace sf::scene {

struct SceneDefaults {
  SceneGeometry geometry;
  Vec3 light_direction{0.35, -1.0, 0.25};  // ortho direction; perspective: default look direction
  PerspectiveCamera camera;                // width/height are set by the caller
  double light_size = 0.2;                 // area-light side, world units
  // The soft reference averages over the pixel (SceneSetup::pixel_average).
  bool pixel_average = false;
  // View depths a cascade layout covers (--camera-near/--camera-far); 0 = derived from the
  // bounding box as seen from the camera (layer_render.hpp, default_view_depths).
  double camera_near = 0.0;
  double camera_far = 0.0;
  std::string purpose;  // what the scene is for (scene.json)
  std::string source;   // mesh file, or "built-in"
};

// spheres, fence, backyard, contact, thin, terrain, city, treeline, grazing.
const std::vector<std::string>& builtin_scene_names();
bool is_builtin_scene(const std::string& name);
SceneDefaults make_builtin_scene(const std::string& name);

// OBJ, PLY, OFF, STL (anything assimp reads): all meshes of the file, scaled so that the
// largest side of their bounding box is 4 units, centred over a floor of half-size 4 and
// resting on it (y up). Throws InputError when the file cannot be read or holds no triangles.
SceneDefaults load_mesh_scene(const std::string& path);

}  // namespace sf::scene

#pragma once
// Output side of the scene generator: metadata (EXR header attributes, scene.json) and the
// staging directory that makes a generated scene appear all at once.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "scene_frames.hpp"
#include "scene_math.hpp"

namespace sf::scene {

struct SceneSetup;

inline constexpr const char* kGeneratorVersion = "shadowfilter scene 2.0";

struct OutputFile {
  std::string name;
  std::string description;
};

// What scene.json records besides the scene setup.
struct SceneRecord {
  std::string source;  // "built-in" or the mesh file
  std::string purpose;
  double min_occluder_floor_gap = 0.0;
  std::vector<OutputFile> files;  // for scene.json; frame files named "frame_NNN/..." with frames > 1
  FramePlan plan;                 // every frame's camera, view depths and layers
};

// Shortest decimal text that reads back to the same double (locale-independent).
std::string format_number(double value);
std::string json_string(const std::string& text);
std::string json_vector(Vec3 v);

// Header attributes of the light-view images: scene, generator, light type, near, far, basis,
// extents or position/fov (plain strings, no time stamps).
std::map<std::string, std::string> light_attributes(const SceneSetup& setup);
// The area light's sides as every header holds them: light_size, and light_height where the
// light is a rectangle (docs/scenes.md).
void add_light_sides(std::map<std::string, std::string>& attributes, const SceneSetup& setup);
// Header attributes of layer k of a frame's cascade set: io::cascade_layer_attributes (what
// io::load_cascade_set reads back), the scene's light (type, direction, axes, size) and, from the
// layer's matrix, near/far (the world depths along the light of d = 0 and 1) and, for an
// unwarped (orthographic) layer, ortho_extents: the same meaning as in shadowmap.exr.
std::map<std::string, std::string> layer_attributes(const SceneSetup& setup, const sf::CascadeSet& set, int k);

void write_scene_json(const std::filesystem::path& path, const SceneSetup& setup, const SceneRecord& record);

// A hidden directory beside the destination that collects the output files. commit() moves
// them into place: the whole directory is renamed when the destination does not exist yet,
// otherwise each file is renamed over its old version (other files there are left alone).
// Without commit() (an error on the way) the staging directory is removed again.
class StagingDirectory {
 public:
  explicit StagingDirectory(const std::filesystem::path& destination);
  ~StagingDirectory();
  StagingDirectory(const StagingDirectory&) = delete;
  StagingDirectory& operator=(const StagingDirectory&) = delete;

  // A file of the output; a name with a directory part ("frame_000/view.exr") gets its directory.
  std::filesystem::path file(const std::string& name) const;
  void commit(const std::vector<OutputFile>& files);

 private:
  std::filesystem::path destination_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

}  // namespace sf::scene

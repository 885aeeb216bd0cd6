// `shadowfilter scene`: byte-identical output for the same arguments and seed (any thread
// count), real meshes through assimp, and clear errors with no partial directory.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "cli_runner.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

struct SceneRun {
  int exit_code = -1;
  std::string err;
};

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

SceneRun scene_cli(const std::string& args, const std::string& dir) {
  const RunResult r = run_cli("scene " + args, dir);
  return {r.exit_code, r.err};
}

const char* const kFiles[] = {"shadowmap.exr",      "receiver_depth.exr", "receivers.exr",
                              "reference_hard.exr", "reference_soft.exr", "scene.json"};

TEST(SceneCli, SameArgumentsAndSeedGiveIdenticalFiles) {
  const std::string dir = temp_dir("scene_determinism");
  const std::string common = " --size 96 --receivers 80x60 --samples 16 --seed 7 -q";
  ASSERT_EQ(scene_cli("fence -o " + dir + "/a" + common, dir).exit_code, 0);
  ASSERT_EQ(scene_cli("fence -o " + dir + "/b" + common + " --threads 1", dir).exit_code, 0);
  ASSERT_EQ(scene_cli("fence -o " + dir + "/c --size 96 --receivers 80x60 --samples 16 --seed 8 -q", dir).exit_code, 0);
  for (const char* name : kFiles) {
    const std::string a = read_all(fs::path(dir) / "a" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_EQ(a, read_all(fs::path(dir) / "b" / name)) << name << " differs between runs";
  }
  // The seed reaches the soft reference (and only the sampled outputs).
  EXPECT_NE(read_all(fs::path(dir) / "a/reference_soft.exr"), read_all(fs::path(dir) / "c/reference_soft.exr"));
  EXPECT_EQ(read_all(fs::path(dir) / "a/shadowmap.exr"), read_all(fs::path(dir) / "c/shadowmap.exr"));
  // The receivers carry ndl (u v d f ndl): finite on every hit, and the hard reference is 0
  // wherever it is <= 0 (facing away from the light).
  const Receivers rx = io::load_receiver_image(dir + "/a/receivers.exr");
  ASSERT_TRUE(rx.has_ndl);
  const HostImage hard = io::load_depth_map(dir + "/a/reference_hard.exr", {});
  size_t hits = 0, lit_facing_away = 0;
  for (size_t i = 0; i < rx.count(); ++i) {
    if (!std::isfinite(rx.d[i])) continue;
    ++hits;
    EXPECT_TRUE(rx.ndl[i] >= -1.0f && rx.ndl[i] <= 1.0f) << i;
    lit_facing_away += rx.ndl[i] <= 0.0f && hard.data[i] != 0.0f;
  }
  EXPECT_GT(hits, 1000u);
  EXPECT_EQ(lit_facing_away, 0u);
}

TEST(SceneCli, MeshFileOnAFloor) {
  const std::string dir = temp_dir("scene_mesh");
  {
    std::ofstream obj(dir + "/tetra.obj");
    obj << "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 0 1.5 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    std::ofstream off(dir + "/quad.off");
    off << "OFF\n4 1 0\n0 0 0\n1 0 0\n1 0 1\n0 0.2 1\n4 0 1 2 3\n";
  }
  for (const char* mesh : {"tetra.obj", "quad.off"}) {
    const std::string out = dir + "/out_" + mesh;
    const SceneRun r = scene_cli(dir + "/" + mesh + " -o " + out + " --size 64 --receivers 64x48 --samples 4 -q", dir);
    ASSERT_EQ(r.exit_code, 0) << mesh << ": " << r.err;
    for (const char* name : kFiles) EXPECT_TRUE(fs::exists(fs::path(out) / name)) << name;
    const std::string json = read_all(fs::path(out) / "scene.json");
    EXPECT_NE(json.find("\"type\": \"mesh\""), std::string::npos);
  }
}

TEST(SceneCli, PerspectiveLightRecordsFovAndPosition) {
  const std::string dir = temp_dir("scene_perspective");
  const SceneRun r = scene_cli("spheres -o " + dir +
                                   "/p --size 64 --receivers 64x48 --samples 4 -q "
                                   "--light perspective --light-pos 3,9,2 --fov 70 --light-size 0.3",
                               dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json = read_all(fs::path(dir) / "p/scene.json");
  EXPECT_NE(json.find("\"type\": \"perspective\""), std::string::npos);
  EXPECT_NE(json.find("\"fov_degrees\": 70"), std::string::npos);
  EXPECT_NE(json.find("\"position\": [3, 9, 2]"), std::string::npos);
  EXPECT_NE(json.find("\"size\": 0.3"), std::string::npos);
}

class SceneCliErrors : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(SceneCliErrors, ClearErrorAndNoDirectory) {
  const auto& [args, expect] = GetParam();
  const std::string dir = temp_dir("scene_errors_" + std::to_string(std::hash<std::string>{}(args)));
  { std::ofstream(dir + "/garbage.obj") << "this is not a mesh\n\x01\x02\n"; }
  std::string a = args;
  for (size_t p; (p = a.find("@")) != std::string::npos;) a.replace(p, 1, dir);
  const SceneRun r = scene_cli(a + " -o " + dir + "/out", dir);
  EXPECT_EQ(r.exit_code, 2) << a << "\n" << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << "stderr: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u) << "something besides garbage.obj was left in " << dir;
}

INSTANTIATE_TEST_SUITE_P(BadArguments, SceneCliErrors,
                         ::testing::Values(std::make_pair("nosuchscene", "unknown scene 'nosuchscene'"),
                                           std::make_pair("@/missing.ply", "file not found"),
                                           std::make_pair("@/garbage.obj", "holds no triangles"),
                                           std::make_pair("spheres --size 0", "--size must be between 1"),
                                           std::make_pair("spheres --receivers 0x10", "--receivers width"),
                                           std::make_pair("spheres --samples 10", "square number"),
                                           std::make_pair("spheres --light sideways", "--light must be"),
                                           std::make_pair("spheres --light-pos 1,2,3", "needs --light perspective"),
                                           std::make_pair("spheres --light-dir 0,0,0", "zero vector"),
                                           std::make_pair("spheres --light perspective --light-pos 0,1,0",
                                                          "behind the light")));

}  // namespace
}  // namespace sf::test

#include "scene_library.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include "mesh_file.hpp"
#include "scene_files.hpp"
#include "shadowfilter/errors.hpp"
#include "output_file.hpp"

namespace sf::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFloorHalfSize = 4.0;

// Deterministic generator for procedural geometry (independent of --seed and of the library).
struct Rng {
  uint64_t state;
  double next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }
  double range(double lo, double hi) { return lo + (hi - lo) * next(); }
};

// Oblique view from above one corner, so footprints grow with distance; the floor does not
// fill the frame (background pixels are NaN receivers).
PerspectiveCamera corner_camera() {
  PerspectiveCamera camera;
  camera.position = {7.0, 5.5, 9.0};
  camera.target = {0.0, 0.4, -0.5};
  camera.vertical_fov_degrees = 42.0;
  return camera;
}

SceneDefaults spheres() {
  SceneDefaults s;
  s.geometry.name = "spheres";
  s.purpose = "basic case: floating sphere and box over a floor (umbra gap >= 0.1 for ESM)";
  add_floor(s.geometry, kFloorHalfSize);
  // Both occluders float above the floor so that every occluder-floor pair is at least
  // 0.15 apart in normalised light depth (ESM with c = 80 is then < 1e-3 in the umbra).
  add_sphere(s.geometry, "sphere", {-1.3, 2.2, 0.9}, 0.9);
  add_box(s.geometry, "box", {0.4, 1.2, -2.2}, {2.2, 2.0, -0.6});
  s.light_direction = {0.35, -1.0, 0.25};
  s.camera = corner_camera();
  s.light_size = 0.2;
  return s;
}

// A picket fence between the light and a box and a sphere: thin high-frequency occluders in
// front of other objects (VSM light bleeding, Annen 2008 fig. 6.9 / 7.8).
SceneDefaults fence() {
  SceneDefaults s;
  s.geometry.name = "fence";
  s.purpose =
      "thin high-frequency occluder (picket fence) in front of other objects: VSM light "
      "bleeding (Annen 2008 fig. 6.9, 7.8)";
  add_floor(s.geometry, kFloorHalfSize);
  for (int k = 0; k < 40; ++k) {
    const double x = -3.6 + 0.18 * k;
    add_box(s.geometry, "slat" + std::to_string(k), {x, 0.0, 2.0}, {x + 0.07, 2.4, 2.05});
  }
  add_box(s.geometry, "rail_low", {-3.7, 0.6, 2.05}, {3.7, 0.7, 2.1});
  add_box(s.geometry, "rail_high", {-3.7, 1.9, 2.05}, {3.7, 2.0, 2.1});
  add_box(s.geometry, "box", {-1.8, 0.0, -0.2}, {-0.2, 0.9, 1.2});
  add_sphere(s.geometry, "sphere", {1.5, 0.7, 0.5}, 0.7);
  s.light_direction = {0.2, -1.0, -1.1};
  s.camera.position = {7.5, 6.0, -6.5};
  s.camera.target = {0.0, 0.3, 0.6};
  s.camera.vertical_fov_degrees = 40.0;
  s.light_size = 0.1;
  return s;
}

void add_table(SceneGeometry& g, const std::string& name, Vec3 lo, Vec3 hi, double top, double leg) {
  add_box(g, name + "_top", {lo.x, hi.y - top, lo.z}, hi);
  const double xs[2] = {lo.x, hi.x - leg}, zs[2] = {lo.z, hi.z - leg};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      add_box(g, name + "_leg" + std::to_string(2 * a + b), {xs[a], 0.0, zs[b]},
              {xs[a] + leg, hi.y - top, zs[b] + leg});
}

// Several depth layers over each other: tree crown, table top, bench, shed roof, a ball
// (ESM failure classification, Annen 2008 table 7.2).
SceneDefaults backyard() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "backyard";
  s.purpose =
      "several depth layers (tree crown over table over bench over floor): ESM failure "
      "classification (Annen 2008 table 7.2)";
  add_floor(g, kFloorHalfSize);
  add_table(g, "table", {-2.6, 0.0, -2.6}, {-0.6, 1.1, -1.2}, 0.08, 0.1);
  add_table(g, "bench", {-1.2, 0.0, -0.6}, {0.6, 0.5, -0.1}, 0.06, 0.08);
  add_box(g, "bench_back", {-1.2, 0.5, -0.1}, {0.6, 1.0, -0.04});
  TriMesh trunk;
  trunk.name = "trunk";
  add_prism(trunk, {-1.0, 0.0, -2.9}, {-1.0, 2.6, -2.9}, 0.16, 0.1, 10);
  g.meshes.push_back(trunk);
  g.description.push_back(
      "{\"type\": \"prism\", \"name\": \"trunk\", \"from\": [-1, 0, -2.9], "
      "\"to\": [-1, 2.6, -2.9], \"radii\": [0.16, 0.1], \"sides\": 10}");
  add_sphere(g, "crown", {-1.0, 3.1, -2.6}, 0.95);
  add_box(g, "shed", {1.2, 0.0, 1.0}, {3.4, 1.5, 3.2});
  add_quad(g, "shed_roof", {1.0, 1.45, 0.8}, {2.6, 0.0, 0.0}, {0.0, 0.7, 2.6});
  add_sphere(g, "ball", {1.2, 0.35, -1.6}, 0.35);
  add_box(g, "planter", {2.0, 0.0, -3.4}, {3.4, 0.4, -2.6});
  add_sphere(g, "bush", {2.7, 0.75, -3.0}, 0.45);
  s.light_direction = {-0.3, -1.0, -0.35};
  s.camera = corner_camera();
  s.light_size = 0.15;
  return s;
}

// A slanted plane whose lower edge lies on the floor, a box and a ball resting on the floor:
// contact shadows (low-order CSM brightening, Annen 2008 fig. 6.5).
SceneDefaults contact() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "contact";
  s.purpose =
      "slanted plane touching the floor, box and ball resting on it: contact shadows, "
      "low-order CSM brightening (Annen 2008 fig. 6.5)";
  add_floor(g, kFloorHalfSize);
  add_quad(g, "ramp", {-2.8, 0.0, -2.0}, {0.0, 0.0, 3.2}, {2.6, 1.5, 0.0});
  add_box(g, "box", {0.9, 0.0, -2.6}, {2.3, 1.0, -1.2});
  add_sphere(g, "ball", {1.6, 0.6, 1.6}, 0.6);
  add_box(g, "plank", {-0.5, 0.0, 2.2}, {2.5, 0.12, 2.6});
  s.light_direction = {0.45, -1.0, 0.2};
  s.camera = corner_camera();
  s.light_size = 0.15;
  return s;
}

// A lattice of thin slats 1.5 over the floor throws a fine grid of shadows on it, seen from 0.4
// above the floor along its length: footprints tens of texels long along the view and a few
// across, the ground at a grazing angle of Annen 2008 sec. 6.2 (fig. 6.6, 7.7), where an
// isotropic footprint over-blurs the shadow lines that run away from the camera.
SceneDefaults grazing() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "grazing";
  s.purpose =
      "a lattice's grid of shadows on a floor seen from 0.4 above it: grazing footprints, anisotropic "
      "filtering (Annen 2008 sec. 6.2, fig. 6.6, 7.7)";
  add_floor(g, kFloorHalfSize);
  constexpr int kSlats = 24;
  constexpr double kPitch = 8.0 / kSlats, kWidth = 0.07, kLow = 1.5, kHigh = 1.56;
  for (int k = 0; k < kSlats; ++k) {
    const double a = -4.0 + kPitch * (k + 0.5) - 0.5 * kWidth;
    add_box(g, "slat_x" + std::to_string(k), {-4.0, kLow, a}, {4.0, kHigh, a + kWidth});
    add_box(g, "slat_z" + std::to_string(k), {a, kHigh, -4.0}, {a + kWidth, kHigh + 0.06, 4.0});
  }
  s.light_direction = {0.12, -1.0, 0.18};
  // 15 degrees down with a 30 degree field: the top row looks along the horizon, the floor's far
  // edge 7.9 away is seen at 3 degrees (footprints about 20 times longer than wide there).
  s.camera.position = {0.3, 0.4, 3.9};
  s.camera.target = {-0.2, 0.4 - 7.9 * std::tan(15.0 * kPi / 180.0), -4.0};
  s.camera.vertical_fov_degrees = 30.0;
  // A small light: shadow lines a few texels wide with sharp edges, which filtering must neither
  // alias nor smear across.
  s.light_size = 0.02;
  // Its soft reference is the pixel's average: what a filtered lookup of a pixel estimates, where
  // the lattice's lines are finer than a pixel (the centre's value would score aliasing).
  s.pixel_average = true;
  return s;
}

void grow_branch(TriMesh& mesh, Rng& rng, Vec3 base, Vec3 dir, double len, double radius, int depth) {
  const Vec3 tip = base + len * dir;
  add_prism(mesh, base, tip, radius, radius * 0.75, depth > 3 ? 6 : 4);
  if (depth == 0) return;
  const int children = depth > 4 ? 2 : 3;
  for (int c = 0; c < children; ++c) {
    const double spin = 2.0 * kPi * (c + rng.next() * 0.5) / children;
    const double tilt = rng.range(0.45, 0.8);
    const Vec3 helper = std::abs(dir.y) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    const Vec3 e1 = normalize(cross(dir, helper));
    const Vec3 e2 = cross(dir, e1);
    const Vec3 side = std::cos(spin) * e1 + std::sin(spin) * e2;
    Vec3 child = normalize(std::cos(tilt) * dir + std::sin(tilt) * side + Vec3{0, 0.15, 0});
    grow_branch(mesh, rng, tip, child, len * rng.range(0.68, 0.78), radius * 0.72, depth - 1);
  }
}

// Two trees of branches down to sub-texel width: aliasing and minification (Annen 2008
// fig. 6.6, 6.10).
SceneDefaults thin() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "thin";
  s.purpose =
      "tree-like branches down to sub-texel width: aliasing and minification (Annen 2008 "
      "fig. 6.6, 6.10)";
  add_floor(g, kFloorHalfSize);
  Rng rng{20240601};
  const Vec3 roots[2] = {{-1.2, 0.0, -0.8}, {1.6, 0.0, -2.2}};
  const double heights[2] = {1.4, 1.1};
  for (int k = 0; k < 2; ++k) {
    TriMesh tree;
    tree.name = "tree" + std::to_string(k);
    grow_branch(tree, rng, roots[k], {0.0, 1.0, 0.0}, heights[k], 0.09, 7);
    g.description.push_back("{\"type\": \"tree\", \"name\": " + json_string(tree.name) + ", \"root\": " +
                            json_vector(roots[k]) + ", \"trunk_length\": " + format_number(heights[k]) +
                            ", \"levels\": 8, \"triangles\": " + std::to_string(tree.triangles.size()) + "}");
    g.meshes.push_back(std::move(tree));
  }
  s.light_direction = {0.3, -1.0, 0.2};
  s.camera = corner_camera();
  s.light_size = 0.1;
  return s;
}

// A ground mesh over |x|, |z| <= half: cells x cells squares of two triangles each, the vertex
// of grid point (i, j) at height(x, z).
TriMesh height_field(const std::string& name, double half, int cells, double (*height)(double, double)) {
  TriMesh mesh;
  mesh.name = name;
  mesh.ground = true;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const double x = -half + 2.0 * half * i / cells;
      const double z = -half + 2.0 * half * j / cells;
      mesh.vertices.push_back({x, height(x, z), z});
    }
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
      mesh.triangles.push_back({a, c, b});
      mesh.triangles.push_back({b, c, d});
    }
  return mesh;
}

double terrain_height(double x, double z) {
  return 0.9 + 0.55 * std::sin(0.8 * x + 0.4) * std::cos(0.65 * z - 0.3) + 0.3 * std::sin(1.7 * x + 1.3 * z + 2.0) +
         0.14 * std::sin(3.1 * x - 2.6 * z + 0.7) + 0.07 * std::cos(5.3 * x + 4.1 * z + 1.9) +
         0.035 * std::sin(9.7 * x - 7.9 * z);
}

// A self-shadowing height field under a low light: shadow acne and bias (the terrain is the
// ground: receiver_depth.exr is its own depth).
SceneDefaults terrain() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "terrain";
  s.purpose = "self-shadowing height field under a low light: acne and bias";
  constexpr int kCells = 200;
  g.meshes.push_back(height_field("terrain", kFloorHalfSize, kCells, terrain_height));
  g.description.push_back(
      "{\"type\": \"height_field\", \"name\": \"terrain\", \"extent\": [-4, 4], \"cells\": 200, "
      "\"height\": \"0.9 + 0.55 sin(0.8x+0.4) cos(0.65z-0.3) + 0.3 sin(1.7x+1.3z+2) + 0.14 "
      "sin(3.1x-2.6z+0.7) + 0.07 cos(5.3x+4.1z+1.9) + 0.035 sin(9.7x-7.9z)\"}");
  s.light_direction = {1.0, -0.55, 0.35};
  s.camera.position = {-6.5, 5.5, 7.5};
  s.camera.target = {0.3, 0.6, -0.5};
  s.camera.vertical_fov_degrees = 45.0;
  s.light_size = 0.1;
  return s;
}

// --- Large scenes in metres (Oliveira 2009: cascades and warping). World units are metres; the
// camera stands near the ground and looks across hundreds of metres, so a single map spends
// most of its texels far away and PSSM / TSM have something to fix.

// A sun `elevation_degrees` above the horizon, shining along the horizontal (x, z) direction.
Vec3 sun_direction(double elevation_degrees, double x, double z) {
  const double e = elevation_degrees * kPi / 180.0;
  const double h = std::hypot(x, z);
  return {std::cos(e) * x / h, -std::sin(e), std::cos(e) * z / h};
}

// Sparse city blocks on a 2 km x 2 km ground: a street grid of 100 m (80 m blocks, 20 m
// streets), each block a park or up to four lots with one box building each; tall buildings
// (40-150 m) cluster towards the centre, the rest are 5-15 m. Fixed seed: the same city always.
SceneDefaults city() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "city";
  s.purpose =
      "sparse city blocks over 2 km x 2 km seen from street level: shadows from 5 m to 1.5 km "
      "away, PSSM and TSM (Oliveira 2009)";
  constexpr double kHalf = 1000.0, kPitch = 100.0, kStreet = 20.0, kLot = 0.5 * (kPitch - kStreet);
  constexpr int kBlocks = int(2.0 * kHalf / kPitch);
  add_floor(g, kHalf);
  Rng rng{20260115};
  TriMesh buildings;
  buildings.name = "buildings";
  int tall = 0, low = 0;
  for (int bz = 0; bz < kBlocks; ++bz)
    for (int bx = 0; bx < kBlocks; ++bx) {
      const double x0 = -kHalf + bx * kPitch + 0.5 * kStreet, z0 = -kHalf + bz * kPitch + 0.5 * kStreet;
      if (rng.next() < 0.2) continue;  // a park
      const double r = std::hypot(x0 + kLot, z0 + kLot);
      const double p_tall = 0.05 + 0.35 * std::exp(-(r / 500.0) * (r / 500.0));
      for (int lot = 0; lot < 4; ++lot) {
        if (rng.next() > 0.75) continue;
        const double lx = x0 + (lot & 1) * kLot, lz = z0 + (lot >> 1) * kLot;
        const double w = rng.range(15.0, kLot - 4.0), d = rng.range(15.0, kLot - 4.0);
        const double ox = lx + rng.range(2.0, kLot - 2.0 - w), oz = lz + rng.range(2.0, kLot - 2.0 - d);
        const bool is_tall = rng.next() < p_tall;
        const double h = is_tall ? rng.range(40.0, 150.0) : rng.range(5.0, 15.0);
        (is_tall ? tall : low)++;
        append_box(buildings, {ox, 0.0, oz}, {ox + w, h, oz + d});
      }
    }
  g.description.push_back("{\"type\": \"city\", \"name\": \"buildings\", \"blocks\": [" + std::to_string(kBlocks) +
                          ", " + std::to_string(kBlocks) + "], \"block_pitch\": 100, \"street_width\": 20, " +
                          "\"tall_buildings\": " + std::to_string(tall) + ", \"low_buildings\": " +
                          std::to_string(low) + ", \"heights\": {\"tall\": [40, 150], \"low\": [5, 15]}, " +
                          "\"triangles\": " + std::to_string(buildings.triangles.size()) + "}");
  g.meshes.push_back(std::move(buildings));
  // From the west and a little behind the camera: buildings throw their shadows across the
  // north-south streets, and the facades facing the camera are lit at a grazing angle.
  s.light_direction = sun_direction(36.0, 0.95, 0.15);
  // Over the street x = 0 near the south edge, 30 m up, looking north along the street and a
  // little down: the ground from ~45 m to the far side of the city.
  s.camera.position = {0.0, 30.0, -960.0};
  s.camera.target = {60.0, 0.0, -200.0};
  s.camera.vertical_fov_degrees = 60.0;
  s.camera_near = 1.0;
  s.camera_far = 1500.0;
  // The orthographic area light lies in the near plane, so its penumbra is L (d_R - d_B) / d_R:
  // L = 8 m is the sun's half degree at d_R ~ 900 m, a typical receiver depth here.
  s.light_size = 8.0;
  return s;
}

double treeline_height(double x, double z) {
  return 12.0 * std::sin(x / 170.0 + 0.3) * std::cos(z / 210.0 - 0.5) + 6.0 * std::sin((x + z) / 90.0 + 1.0) +
         2.0 * std::sin(x / 37.0 - z / 45.0);
}

// Gentle terrain over 1 km x 1 km (slopes under ~12 degrees) with seven rows of thin trees
// (windbreaks): a trunk prism and a narrow crown cone each, 8-25 m tall. Fixed seed.
SceneDefaults treeline() {
  SceneDefaults s;
  SceneGeometry& g = s.geometry;
  g.name = "treeline";
  s.purpose =
      "rows of thin trees on gentle terrain over 1 km x 1 km seen from eye height: thin far "
      "occluders, self-shadowing ground, PSSM and TSM (Oliveira 2009)";
  constexpr double kHalf = 500.0;
  constexpr int kCells = 80;
  g.meshes.push_back(height_field("terrain", kHalf, kCells, treeline_height));
  g.description.push_back(
      "{\"type\": \"height_field\", \"name\": \"terrain\", \"extent\": [-500, 500], \"cells\": 80, "
      "\"height\": \"12 sin(x/170+0.3) cos(z/210-0.5) + 6 sin((x+z)/90+1) + 2 sin(x/37-z/45)\"}");
  constexpr int kRows = 7;
  Rng rng{20260116};
  TriMesh trees;
  trees.name = "trees";
  int count = 0;
  for (int row = 0; row < kRows; ++row) {
    const double z0 = -420.0 + 140.0 * row + rng.range(-10.0, 10.0);
    const double slope = rng.range(-0.15, 0.15);
    for (double x = -470.0 + rng.range(0.0, 10.0); x < 470.0; x += rng.range(8.0, 14.0)) {
      const double tx = x, tz = z0 + slope * x + rng.range(-2.0, 2.0);
      const double height = rng.range(8.0, 25.0);
      // Sunk 0.3 m into the ground so that no slope opens a gap under the trunk.
      const Vec3 base{tx, treeline_height(tx, tz) - 0.3, tz};
      const Vec3 up{0.0, 1.0, 0.0};
      add_prism(trees, base, base + (0.4 * height + 0.3) * up, 0.15 + 0.012 * height, 0.1 + 0.01 * height, 6);
      add_prism(trees, base + (0.25 * height + 0.3) * up, base + (height + 0.3) * up, rng.range(0.14, 0.2) * height,
                0.1, 6);
      ++count;
    }
  }
  g.description.push_back("{\"type\": \"trees\", \"name\": \"trees\", \"rows\": " + std::to_string(kRows) +
                          ", \"trees\": " + std::to_string(count) +
                          ", \"heights\": [8, 25], \"parts\": \"trunk prism (6 sides) + crown cone (6 sides)\", "
                          "\"triangles\": " +
                          std::to_string(trees.triangles.size()) + "}");
  g.meshes.push_back(std::move(trees));
  s.light_direction = sun_direction(38.0, 0.3, -0.73);
  // 8 m over the ground (a raised hide) near the south edge, 60 m before the first row, looking
  // north across the rows; the sun is ahead, so each row's shadow falls towards the camera.
  const double cx = -60.0, cz = -480.0, tx = 40.0, tz = 200.0;
  s.camera.position = {cx, treeline_height(cx, cz) + 8.0, cz};
  s.camera.target = {tx, treeline_height(tx, tz) + 2.0, tz};
  s.camera.vertical_fov_degrees = 55.0;
  s.camera_near = 1.0;
  s.camera_far = 1200.0;
  s.light_size = 4.0;  // the sun's half degree at d_R ~ 450 m (see city())
  return s;
}

using Maker = std::function<SceneDefaults()>;

const std::vector<std::pair<std::string, Maker>>& makers() {
  static const std::vector<std::pair<std::string, Maker>> list = {
      {"spheres", spheres}, {"fence", fence}, {"backyard", backyard}, {"contact", contact}, {"thin", thin},
      {"terrain", terrain}, {"city", city},   {"treeline", treeline}, {"grazing", grazing}};
  return list;
}

}  // namespace

const std::vector<std::string>& builtin_scene_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [name, maker] : makers()) n.push_back(name);
    return n;
  }();
  return names;
}

bool is_builtin_scene(const std::string& name) {
  const auto& names = builtin_scene_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

SceneDefaults make_builtin_scene(const std::string& name) {
  for (const auto& [n, maker] : makers()) {
    if (n == name) {
      SceneDefaults s = maker();
      s.source = "built-in";
      return s;
    }
  }
  throw InputError("unknown scene '" + name + "'");
}

SceneDefaults load_mesh_scene(const std::string& path) {
  io::record_input(path);
  namespace fs = std::filesystem;
  TriMesh mesh = read_mesh_file(path);
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Vec3& v : mesh.vertices) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (!(extent > 0.0) || !std::isfinite(extent)) throw InputError("mesh '" + path + "': degenerate bounding box");
  const double scale = kFloorHalfSize / extent;
  const Vec3 shift{-0.5 * (lo.x + hi.x), -lo.y, -0.5 * (lo.z + hi.z)};
  for (Vec3& v : mesh.vertices) v = scale * (v + shift);
  const double height = scale * (hi.y - lo.y);

  SceneDefaults s;
  s.geometry.name = mesh.name;
  s.source = path;
  s.purpose = "real mesh on a floor";
  add_floor(s.geometry, kFloorHalfSize);
  s.geometry.description.push_back("{\"type\": \"mesh\", \"name\": " + json_string(mesh.name) +
                                   ", \"file\": " + json_string(fs::path(path).filename().string()) +
                                   ", \"vertices\": " + std::to_string(mesh.vertices.size()) + ", \"triangles\": " +
                                   std::to_string(mesh.triangles.size()) + ", \"scale\": " + format_number(scale) +
                                   ", \"translation_before_scale\": " + json_vector(shift) + "}");
  s.geometry.meshes.push_back(std::move(mesh));
  s.light_direction = {0.35, -1.0, 0.25};
  s.camera = corner_camera();
  s.camera.target = {0.0, 0.4 * height, -0.3};
  s.light_size = 0.2;
  return s;
}

}  // namespace sf::scene

#pragma once
// Coherent shadow maps (methods.md sec. 5; Ritschel 2007): a stack of N orthographic
// dual-depth maps rendered from a lat-long grid of directions around an object, ordered so that
// neighbours in the sequence look alike, and compressed per texel into piecewise-constant
// segments that separate the first surface (z1) from the second (z2, or the third for closed
// meshes). Visibility of a point toward a direction is a depth test in the view whose grid cell
// holds the direction. docs/coherent.md has the file format and the measured figures.
//
// This header is the layout, the view geometry and the device API; the scalar compression and
// lookup are in host/reference/coherent_reference.hpp, the file in host/io/coherent_file.hpp, the
// Embree renderer of stacks in host/scene/coherent_stack.hpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::coherent {

// Depths are linear along a view and quantised over the bounding sphere's diameter: 0 on the
// view's camera plane (tangent to the sphere, in front of it), kDepthMax on the plane behind it.
// A depth of kDepthMax + 1 = kNoSurface marks "no surface before the far plane" in z1 and
// "+infinity" in z2, so that a texel that misses the object is lit for every query.
inline constexpr uint32_t kDepthMax = 65534;
inline constexpr uint16_t kNoSurface = 65535;
// Views in one stack: 2048 x 2048 (4,194,304 maps), twice the seed's largest grid. View indices
// are 32-bit; the file stores them in 16 bits up to 65536 views (index_bytes).
inline constexpr int kMaxViews = 1 << 22;

// The enumeration of the grid's views into a sequence (Ritschel 2007 sec. 4.4, fig. 8).
enum class Ordering : uint32_t { ScanLine = 0, ZigZag = 1, Hilbert = 2 };
// Which surfaces bound the separating depth: the first and second hit (any mesh), or the first
// and third (closed meshes: the second is the first surface's own back; sec. 3.1).
enum class DepthPair : uint32_t { FirstSecond = 12, FirstThird = 13 };
// A missing upper surface: the exit from the bounding sphere (keeps z_avg on the object, right for
// several objects, sec. 3.1 and 4.6), or +infinity (longer segments).
enum class FarPlane : uint32_t { Sphere = 0, Infinite = 1 };

const char* ordering_name(Ordering o);  // "scanline", "zigzag", "hilbert"
bool parse_ordering(const std::string& s, Ordering* o);
const char* far_plane_name(FarPlane f);  // "sphere", "infinite"
bool parse_far_plane(const std::string& s, FarPlane* f);

// The views and their maps. Grid cell (row j, column k), grid index j * views_phi + k, looks
// along -dir from the sphere's surface, dir = (sin t cos p, cos t, sin t sin p) (y up) at the
// cell's centre t = (j + 1/2) pi / views_theta, p = (k + 1/2) 2 pi / views_phi.
struct StackLayout {
  int views_theta = 32;  // grid rows (polar angle)
  int views_phi = 32;    // grid columns (azimuth)
  int resolution = 128;  // M: texels per side of each map
  Ordering ordering = Ordering::Hilbert;
  DepthPair depth_pair = DepthPair::FirstSecond;
  FarPlane far_plane = FarPlane::Sphere;
  Vec3 center{0.0, 0.0, 0.0};  // bounding sphere of the object
  double radius = 1.0;

  int views() const { return views_theta * views_phi; }
  size_t texels() const { return size_t(resolution) * size_t(resolution); }
  // What the seed's Table 1 counts as uncompressed: one 16-bit depth per texel of every map.
  size_t uncompressed_bytes() const { return size_t(views()) * texels() * 2; }
};
// Throws InputError naming the field: grid sides >= 1 and views() <= kMaxViews; Hilbert needs a
// square grid whose side is a power of two; resolution in [1, 4096]; radius finite and > 0.
void validate(const StackLayout& layout);

// sequence[i] = grid index of the i-th map of the stack (a permutation of 0 .. views() - 1).
std::vector<uint32_t> enumerate_views(const StackLayout& layout);
// position[g] = where grid index g stands in the sequence (the inverse permutation).
std::vector<uint32_t> sequence_positions(const StackLayout& layout);

// A view's frame: dir from the centre toward the camera, right and up span its map (texel x
// along right, y along up; right = d dir / d p normalised, up = dir x right).
struct ViewFrame {
  Vec3 dir, right, up;
};
ViewFrame view_frame(const StackLayout& layout, uint32_t grid_index);
// The grid cell that holds direction d (any length > 0): the view of a query toward d.
uint32_t view_of_direction(const StackLayout& layout, const Vec3& d);

// A point in a view: texel (x, y), possibly outside the map, and its quantised depth
// q = round(depth kDepthMax) clamped to [0, kDepthMax].
struct ViewPoint {
  int x = 0, y = 0;
  uint32_t q = 0;
  bool inside(int resolution) const { return x >= 0 && y >= 0 && x < resolution && y < resolution; }
};
ViewPoint project(const StackLayout& layout, uint32_t grid_index, const Vec3& p);

// --- depth cube maps of a fixed local light (Ritschel 2007 sec. 3.3 and 4.2) -----------------------
// A rectangular light corner + s edge_a + t edge_b (a linear light: samples_b = 1 and edge_b
// zero), sampled at the centres of a samples_a x samples_b grid of cells: grid cell g = b
// samples_a + a has its sampling point at corner + (a + 1/2)/A edge_a + (b + 1/2)/B edge_b and
// its depth cube map, six perspective maps of 90 degrees. The N = A B cube maps are one stack
// of 6 N maps (cube_layout: views_theta 6, views_phi N), map k N + i being face k of the i-th
// cube map in the grid's ordering, so that each texel's depth functions of the six faces are
// concatenated as the seed concatenates them (fig. 5). Depths are planar (along the face's
// axis), quantised over [0, far]: far is the farthest the object reaches from a sampling point.
struct LocalLight {
  Vec3 corner{0.0, 0.0, 0.0}, edge_a{1.0, 0.0, 0.0}, edge_b{0.0, 0.0, 1.0};
  int samples_a = 8, samples_b = 8;
  Ordering ordering = Ordering::Hilbert;  // of the sampling grid (Hilbert: square, power of two)
  double far = 1.0;
  // A mesh light instead of a rectangle: its sampling points on the surface (unit normals beside
  // them), already in the order of their cube maps, each standing for area / count() of it; then
  // samples_a = count(), samples_b = 1, ordering ScanLine, and the rectangle is unused.
  std::vector<Vec3> points, normals;
  double area = 0.0;

  bool is_mesh() const { return !points.empty(); }
  int count() const { return is_mesh() ? int(points.size()) : samples_a * samples_b; }
  Vec3 sample_point(uint32_t grid) const;
};
inline constexpr int kMaxLightSamples = 1 << 16;
// InputError naming the field: finite corner and edges, a non-zero edge_a, edge_b non-zero unless
// samples_b is 1, 1 <= samples, count() <= kMaxLightSamples, the ordering valid for the grid,
// far finite and > 0; a mesh light: as many finite unit normals as finite points, samples_a =
// count(), samples_b = 1, ScanLine, area finite and > 0.
void validate(const LocalLight& light);
// The stack of the light's cube maps around an object's bounding sphere (center, radius):
// 6 x N maps of resolution^2, ordering ScanLine (the faces), FirstSecond, far plane Infinite.
StackLayout cube_layout(const LocalLight& light, int resolution, const Vec3& center, double radius);
// sequence[i]: the grid cell of the i-th cube map in the light's ordering; position[g]: where
// grid cell g stands in it (the inverse permutation).
std::vector<uint32_t> light_sequence(const LocalLight& light);
std::vector<uint32_t> light_positions(const LocalLight& light);
// The farthest the bounding sphere reaches from a sampling point: max |s - center| + radius.
double light_far(const LocalLight& light, const Vec3& center, double radius);

// Face k of a cube map: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z; texel (x, y) of the face looks along
// n + ((x + 1/2) 2/M - 1) u + ((y + 1/2) 2/M - 1) v.
struct CubeFace {
  Vec3 n, u, v;
};
CubeFace cube_face(int k);
// The face, texel and quantised planar depth of point p seen from sampling point s: the face of
// the largest |component| of p - s (ties: x before y before z), texel coordinates clamped to the
// face.
struct CubePoint {
  int face = 0, x = 0, y = 0;
  uint32_t q = 0;
};
CubePoint cube_project(const LocalLight& light, int resolution, const Vec3& s, const Vec3& p);

// The uncompressed stack: z1 and z2 of map i (position in the sequence) at texel t are
// z1[i * texels() + t], z2[...]. Invariant per element: z1 < z2, or z1 == z2 == kNoSurface (a
// surface pair thinner than one depth step is stored as z2 = z1 + 1).
struct DualDepthStack {
  StackLayout layout;
  std::vector<uint16_t> z1, z2;
};

// Bytes of a view index in the file: 2 up to 65536 views, 4 beyond.
inline int index_bytes(const StackLayout& layout) { return layout.views() <= 65536 ? 2 : 4; }

// The compressed stack: texel t's segments are s = offsets[t] .. offsets[t + 1] - 1, in sequence
// order; segment s covers the maps up to and including last[s] at depth[s] (z_avg). The last
// segment of every texel ends at views() - 1.
struct CompressedStack {
  StackLayout layout;
  std::vector<uint32_t> offsets;  // texels() + 1
  std::vector<uint32_t> last;     // offsets.back(): the last map of each segment
  std::vector<uint16_t> depth;    // offsets.back(): z_avg of each segment
  size_t segment_count() const { return last.size(); }
  // Bytes of the compressed data as the file stores it (offsets, each segment's depth and its
  // index in index_bytes), what Table 1's "compressed" compares.
  size_t compressed_bytes() const { return offsets.size() * 4 + last.size() * size_t(2 + index_bytes(layout)); }
};

// The layout as kernels take it (kernels/coherent/query.clh, sf_coherent_layout).
struct DeviceLayout {
  float cx, cy, cz, radius;
  int32_t resolution, views_theta, views_phi, views;
};
static_assert(sizeof(DeviceLayout) == 32, "DeviceLayout must match sf_coherent_layout");
DeviceLayout device_layout(const StackLayout& layout);

}  // namespace sf::coherent

#pragma once
// Layered shadow maps (methods.md sec. 6; Oliveira 2009): a cascade set is K layers, each a shadow map
// with its own world-to-map transform and the range of view depths it serves, plus the rule that
// picks the layer (or the two blended layers) of a receiver. Single maps, parallel-split cascades
// (PSSM), trapezoidal maps (TSM) and PSSM + TSM are all cascade sets; a caller may build one from
// its own matrices. Nothing here touches a device: the layered filtering is layered_pipeline.hpp.
#include <array>
#include <string>
#include <vector>

#include "shadowfilter/vec3.hpp"

namespace sf {

using Point3 = Vec3;  // a world point (vec3.hpp)

// World -> shadow-map coordinates of one layer: a 4x4 matrix M (row-major) applied to p = (x, y, z, 1),
//   u = (M0 . p) / (M3 . p),  v = (M1 . p) / (M3 . p),  d = M2 . p.
// (u, v) are projective: an orthographic light has M3 = (0, 0, 0, 1), a trapezoidal warp puts its
// perspective into M3. d is not divided by M3 . p: methods.md sec. 1 asks for linear light depth,
// which the blur, the pyramids and the depth tests assume; a warp changes where a depth is stored,
// never its value. Valid where M3 . p > 0.
struct LayerTransform {
  std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

  struct MapPoint {
    double u = 0, v = 0, d = 0, w = 0;  // w = M3 . p (> 0 where the transform is valid)
  };
  MapPoint apply(const Point3& p) const;
  // Gradients of u and v with respect to the world position at p (the warp's Jacobian rows).
  void jacobian_uv(const Point3& p, Point3& du, Point3& dv) const;
  // The world point with map coordinates (u, v, d); false where the 3x3 system is singular there.
  bool unproject(double u, double v, double d, Point3& p) const;
  // The light ray through map point (u, v): the point of depth d = 0 and the unit direction of
  // increasing d, with the depth gained per unit of length along it (> 0). False where singular.
  bool ray(double u, double v, Point3& origin, Point3& direction, double& depth_per_length) const;
};

struct CascadeLayer {
  LayerTransform transform;
  double split_near = 0;  // view depths (distance along the camera's axis) this layer serves
  double split_far = 0;
};

// K layers of equal size, ordered by view depth: layer k serves [split_near, split_far), and
// layer k + 1 starts where layer k ends (the last one includes its split_far).
struct CascadeSet {
  int width = 0;  // every layer's map size in texels
  int height = 0;
  std::vector<CascadeLayer> layers;
  // Blend band: the last `blend` fraction of each layer's view-depth range (every layer but the
  // last) mixes its visibility linearly with the next layer's, so a split shows no seam. 0 = none.
  double blend = 0.1;
};

// Throws InputError naming what is wrong: no layers, more than kMaxCascadeLayers, a non-positive
// size, a non-finite matrix entry or split, splits not increasing or not contiguous, a singular
// transform (its (u, v, d) cannot be inverted at the centre of its map), blend outside [0, 1).
constexpr int kMaxCascadeLayers = 8;
void validate(const CascadeSet& set);

// The layers one receiver reads and their weights (summing to 1); layer -1 = unused. A receiver
// outside every layer (view depth outside the splits, non-finite, or outside every map that could
// serve it) has no layer: it is lit.
struct CascadeChoice {
  int layer[2] = {-1, -1};
  double weight[2] = {0, 0};
};
// The rule (methods.md sec. 6): the layer whose split range holds view_depth; where p falls
// outside that layer's map (u or v outside [0, 1], or w <= 0), the next layer that holds it. In
// the blend band at the end of the chosen layer's range, the next layer takes weight t rising
// linearly from 0 to 1 across the band, if p lies on its map.
CascadeChoice select_cascade(const CascadeSet& set, double view_depth, const Point3& p);

// Footprint of a receiver in layer texels: the larger of |J dp_dx|, |J dp_dy| with J the layer's
// Jacobian in texels (width du, height dv) and dp_dx, dp_dy the world-space offsets to the
// neighbouring pixels. Follows the warp, so the same world footprint covers the right number of
// texels in every layer.
double layer_footprint(const CascadeSet& set, int layer, const Point3& p, const Point3& dp_dx, const Point3& dp_dy);
// The same offsets as the Jacobian of (u W, v H) over the pixel in the layer's texels
// (dudx, dvdx, dudy, dvdy; footprint.hpp): layer_footprint is its longer column's length.
std::array<double, 4> layer_jacobian(const CascadeSet& set, int layer, const Point3& p, const Point3& dp_dx,
                                     const Point3& dp_dy);

// PSSM's practical split scheme (Oliveira 2009 sec. 3.1; Zhang et al.): K + 1 view depths from near to
// far, s_i = lambda n (f/n)^(i/K) + (1 - lambda)(n + (f - n) i / K).
std::vector<double> practical_splits(double near_depth, double far_depth, int count, double lambda);

// --- Fitting layouts to a camera and an orthographic (directional) light. ---

// A pinhole camera: the view depth of a point is its distance along `forward`.
struct CameraFrustum {
  Point3 position{0, 0, 0};
  Point3 forward{0, 0, -1};  // unit
  Point3 up{0, 1, 0};        // unit, orthogonal to forward
  double vertical_fov_degrees = 45;
  double aspect = 16.0 / 9.0;  // width / height
  double near_depth = 0.1;
  double far_depth = 100;
  // The 8 corners of the slice of view depths [a, b]: near face then far face.
  std::array<Point3, 8> slice_corners(double a, double b) const;
};

struct WorldBox {  // an axis-aligned bounding box of some geometry (an occluder or receiver)
  Point3 lo{0, 0, 0};
  Point3 hi{0, 0, 0};
};

enum class LayoutKind { Single, Pssm, Tsm, PssmTsm };
const char* layout_name(LayoutKind kind);          // "single", "pssm", "tsm", "pssm+tsm"
LayoutKind parse_layout(const std::string& name);  // InputError for other names

struct LayoutOptions {
  LayoutKind kind = LayoutKind::Pssm;
  // Layers of pssm and pssm+tsm (single and tsm: 1). Four is what engines ship.
  int cascades = 4;
  // Map size of every layer (texels per side). Equal total texels: one 4096 map = four 2048.
  int map_size = 2048;
  // Practical split blend: 0 uniform, 1 logarithmic. 0.75: the fewest mismatched pixels against
  // the ray-traced reference, near and overall, on city and treeline at 4 x 2048² (0.5, PSSM's
  // paper's compromise, leaves the first cascade 190 m deep in city's 1500 m view;
  // docs/cascades.md).
  double split_lambda = 0.75;
  // Stabilisation (pssm, single): each layer is the square around its slice's bounding sphere,
  // whose size does not change as the camera turns, moved in whole texels along the light's
  // axes, so a static scene's texels stay put from frame to frame (no crawling at the edges of
  // shadows). Off: the tight box of the slice in light space (sharper, flickers).
  bool stabilize = true;
  // TSM's focus point: the view depth that the trapezoid maps to 80% of its map (Oliveira 2009 sec.
  // 3.2, the "80% rule"), as a fraction t of the slice's log range, near (f/n)^t. 0.8: a
  // logarithmic parameterisation (the ideal against perspective aliasing) puts that depth on the
  // 80% line too, so the trapezoid agrees with it there; 0.5, the geometric mean, crushes the far
  // part of a deep slice into a few rows (texels 100 pixels long on city's walls; measured in
  // docs/cascades.md).
  double tsm_focus = 0.8;
  double blend = 0.1;  // CascadeSet::blend
};

// The cascade set of a layout for a camera and a directional light travelling along
// light_direction. geometry: the bounding boxes of the scene's parts (the finer, the tighter each
// layer's depth range: a layer's [near, far] encloses the boxes that overlap its map, and ends at
// the deepest point of its slice). Throws InputError for options outside their bounds.
CascadeSet fit_layout(const LayoutOptions& options, const CameraFrustum& camera, const Point3& light_direction,
                      const std::vector<WorldBox>& geometry);

// World size of one texel of a layer at p (the square root of the area a texel covers on the
// plane facing the light); a uniform layer has the same value everywhere.
double layer_texel_size(const CascadeSet& set, int layer, const Point3& p);

}  // namespace sf

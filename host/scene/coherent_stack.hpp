#pragma once
// The dual-depth stacks of coherent shadow maps (methods.md sec. 5; Ritschel 2007 sec. 3.1 and 4.1):
// the object alone (no floor), its bounding sphere, and its N orthographic views rendered with
// Embree on host threads.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "scene_geometry.hpp"
#include "shadowfilter/coherent.hpp"

namespace sf::scene {

// The object of `coherent build`: a mesh file (OBJ, PLY, OFF, STL: every triangle, placed as
// `scene` places it by load_mesh_scene: largest side 4 units, resting on y = 0), a built-in
// object: "sphere" (unit sphere), "box" (2 x 1 x 1.5, centred), or a built-in scene's occluders
// (its floor left out in both cases). Throws InputError for anything else.
SceneGeometry load_coherent_object(const std::string& source);

// The bounding sphere written into `layout`: centre of the bounding box, radius a hair above
// the farthest point, so every surface lies strictly inside.
void fit_bounding_sphere(const SceneGeometry& object, coherent::StackLayout& layout);

// How the views are rendered: Auto rasterises triangle meshes (view_raster.hpp) and ray-casts
// objects with analytic spheres (Embree); Embree ray-casts everything (the check of the other).
enum class StackRenderer { Auto, Embree };

// Every view of `layout`, map i of the stack being the view enumerate_views(layout)[i].
// threads <= 0: all hardware threads. progress(views done) is called from any thread.
coherent::DualDepthStack render_stack(const SceneGeometry& object, const coherent::StackLayout& layout, int threads,
                                      const std::function<void(size_t)>& progress = {},
                                      StackRenderer renderer = StackRenderer::Auto);

// Maps [first, end) of the stack's sequence (positions, not grid indices): a part of the stack
// that one process renders (`coherent build --shard K/N`).
struct ViewRange {
  uint32_t first = 0, end = 0;
  uint32_t count() const { return end - first; }
};
// The range of part K (index K - 1) of N: positions floor((K - 1) V / N) .. floor(K V / N) of the
// V views, contiguous, so that the parts in order are the whole sequence.
ViewRange shard_views(const coherent::StackLayout& layout, size_t index, size_t count);

// The maps of a range: z1 and z2 of sequence position range.first + i at texel t are
// z1[i * texels() + t], z2[...], as DualDepthStack holds them.
struct StackPart {
  ViewRange range;
  std::vector<uint16_t> z1, z2;
};
// The maps of `range` as render_stack renders them (the same bytes: each view is rendered alone).
// InputError for a range outside the layout's views.
StackPart render_stack_part(const SceneGeometry& object, const coherent::StackLayout& layout, ViewRange range,
                            int threads, const std::function<void(size_t)>& progress = {},
                            StackRenderer renderer = StackRenderer::Auto);

// The depth cube maps of a fixed local light around `object` (Ritschel 2007 sec. 3.3 and 4.2):
// fit_local_light sets light.far from the object's bounding sphere (light_far) and returns the
// stack's layout (cube_layout). Map m of the stack, in sequence order, is face m / N of the cube
// map at position m % N of the light's ordering, ray-cast with Embree from its sampling point
// through every texel centre: the first and second crossing, planar depth quantised over
// [0, far]; a missing second crossing is +infinity.
coherent::StackLayout fit_local_light(const SceneGeometry& object, coherent::LocalLight& light, int resolution);
// Maps [range.first, range.end) of the sequence (a streamed build renders and fits them a chunk
// at a time, in order); threads <= 0: all hardware threads; progress(maps done).
StackPart render_cube_stack_part(const SceneGeometry& object, const coherent::LocalLight& light,
                                 const coherent::StackLayout& layout, ViewRange range, int threads,
                                 const std::function<void(size_t)>& progress = {});
// A mesh light's sampling points: `count` points stratified by area over the mesh's triangles
// (point k in the triangle holding area (k + 1/2) A / count of the area's running sum, spread
// across it by a golden-ratio sequence), each with its triangle's unit normal, sorted along a
// Morton curve through the mesh's bounding box so that neighbouring cube maps see alike.
// InputError when the mesh has no area or count is outside [1, kMaxLightSamples].
coherent::LocalLight mesh_light(const TriMesh& mesh, int count);
// Every map: fit_local_light, then the part of all 6 N maps.
coherent::DualDepthStack render_cube_stack(const SceneGeometry& object, coherent::LocalLight& light, int resolution,
                                           int threads, const std::function<void(size_t)>& progress = {});

}  // namespace sf::scene

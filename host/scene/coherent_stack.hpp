#pragma once
// The dual-depth stacks of coherent shadow maps (methods.md sec. 5; Ritschel 2007 sec. 3.1 and 4.1):
// the object alone (no floor), its bounding sphere, and its N orthographic views rendered with
// Embree on host threads.
#include <functional>
#include <string>

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

}  // namespace sf::scene

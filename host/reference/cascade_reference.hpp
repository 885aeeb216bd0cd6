#pragma once
// The scalar reference of layered filtering (layered.hpp; methods.md sec. 6): per receiver
// sf::select_cascade and, per layer it reads, the layer's map point and footprint in double;
// each layer filtered alone by the per-map reference (ref::filter) with the layer's options
// (sf::layer_filter_options); the chosen layers' visibilities blended by their weights.
#include <vector>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"

namespace sf::ref {

// What sf_cascade_project computes: the choice per receiver and per layer the receivers as that
// layer's reconstruction reads them (u, v, d and f = layer_footprint, rounded to float once; d
// NaN where the layer does not serve the receiver). Receivers::width is the view's width, so the
// receiver plane finds its neighbours in the view. With a normal offset, each layer reads the
// receiver moved that many of its texels along the camera-facing normal -(dx x dy) / |dx x dy|
// (sf_cascade_moved; the layer choice stays the unmoved point's).
struct CascadeProjection {
  std::vector<CascadeChoice> choice;
  std::vector<Receivers> layers;
};
CascadeProjection project_cascades(const CascadeSet& set, const ViewReceivers& view, double normal_offset = 0.0);

// Blended visibility per receiver (1 where no layer serves it; 0 for ndl <= 0 under
// FilterOptions::facing_away_shadowed when the view has ndl).
std::vector<double> filter_cascades(const FilterOptions& options, const CascadeSet& set,
                                    const std::vector<HostImage>& maps, const ViewReceivers& view);
// The same from a given projection (a kernel's, to compare the filtering alone), without the
// facing-away rule (the projection has no ndl).
std::vector<double> filter_cascades(const FilterOptions& options, const CascadeSet& set,
                                    const std::vector<HostImage>& maps, const CascadeProjection& projection);

}  // namespace sf::ref

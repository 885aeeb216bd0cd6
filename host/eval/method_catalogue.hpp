#pragma once
// What evaluate and --auto know of each method, beside evaluate: its plot colour, the label of
// its rows, the parameter variants its grids and --auto try, and --auto's cost coefficients.
// The core's registry (methods.hpp) keeps the kernel facts; this catalogue is keyed by method,
// and a method registered without an entry (a renderer's own) gets the default entry: no
// variants beyond its defaults, the default cost, grey.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "shadowfilter/methods.hpp"

namespace sf::eval {

enum class Grid;  // evaluate.hpp

// --auto's cost estimate in nanoseconds (coefficients measured on PoCL, docs/results.md
// "cost model"): per map texel, transform_per_channel x channels; per receiver, reconstruct +
// reconstruct_per_channel x channels + per_support_texel x (2R + 2)^2.
struct CostModel {
  double transform_per_channel = 0.5;
  double reconstruct = 9.0;
  double reconstruct_per_channel = 0.0;
  double per_support_texel = 0.0;
};

struct CatalogueEntry {
  // The short label of evaluate's rows: the parameters a grid varies (" c=80"); "" for none.
  std::function<std::string(const FilterOptions&)> label;
  // Parameter variants of `base` for a grid (each then crossed with radii, lookups, storages);
  // empty: {base}.
  std::function<std::vector<FilterOptions>(const FilterOptions& base, Grid grid)> variants;
  // --auto's candidates (each then crossed with storages and lookups); empty: the wide grid's.
  std::function<std::vector<FilterOptions>(const FilterOptions& base)> auto_variants;
  bool quick_footprints = false;  // the quick grid also tries the footprint lookups
  CostModel cost;
  std::array<float, 3> colour{0.3f, 0.3f, 0.3f};  // plot colour (fixed: every plot reads the same)
};

// The method's entry, or the default entry for a method the catalogue does not list.
const CatalogueEntry& catalogue_entry(const Method& m);
// Whether the catalogue lists the method by name (the registered ones all are; tested).
bool catalogued(const Method& m);

// The entry's functions with their defaults applied.
std::string catalogue_label(const FilterOptions& o);
std::vector<FilterOptions> grid_variants(const FilterOptions& base, Grid grid);
std::vector<FilterOptions> auto_variants(const FilterOptions& base);

}  // namespace sf::eval

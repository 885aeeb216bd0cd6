#pragma once
// A plan validates its options once (Pipeline::plan, through validate_options). The kernel
// wrappers a Pipeline calls for one pass (enqueue_transform, enqueue_reconstruct_*, the depth
// tests, the classification stage) are public entry points that validate what they are given;
// inside a PlannedScope, opened by the Pipeline around its own passes with the options its plan
// validated, they skip that: a frame is validated by its plan, not once more per kernel.
#include "shadowfilter/methods.hpp"

namespace sf::detail {

class PlannedScope {
 public:
  PlannedScope();
  ~PlannedScope();
  PlannedScope(const PlannedScope&) = delete;
  PlannedScope& operator=(const PlannedScope&) = delete;
};

// m.validate(o), unless this thread is inside a PlannedScope.
void validate_unless_planned(const MethodDesc& m, const FilterOptions& o);

}  // namespace sf::detail

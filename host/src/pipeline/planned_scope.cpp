#include "planned_scope.hpp"

namespace sf::detail {
namespace {

thread_local int planned_depth = 0;  // open PlannedScopes on this thread

}  // namespace

PlannedScope::PlannedScope() { ++planned_depth; }
PlannedScope::~PlannedScope() { --planned_depth; }

void validate_unless_planned(const MethodDesc& m, const FilterOptions& o) {
  if (planned_depth == 0) m.validate(o);
}

}  // namespace sf::detail

#pragma once
// Internal to the reference: one factory per method file, given the method's packed parameters
// (the floats of its sf_method_params, resolved by the registry from FilterOptions).
#include <vector>

#include "reference.hpp"

namespace sf::ref::detail {

MethodRef esm_ref(const std::vector<float>& p, const FilterOptions& opt);
MethodRef vsm_ref(const std::vector<float>& p, const FilterOptions& opt);
MethodRef evsm_ref(const std::vector<float>& p, const FilterOptions& opt, bool four);
MethodRef msm_ref(const std::vector<float>& p, const FilterOptions& opt, bool hausdorff);
MethodRef csm_ref(const std::vector<float>& p, const FilterOptions& opt);

inline bool unorm(Storage s) { return s == Storage::Unorm16 || s == Storage::Unorm8; }

}  // namespace sf::ref::detail

#pragma once
// The build options of a method's programs, shared by the kernel wrappers and kernel_prelude().
#include <string>

#include "launch.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::detail {

// -DSF_METHOD_<name> ('-' becomes '_'), -DSF_STORAGE=<n> and the method's own knobs
// (MethodDesc::defines), added to `b`.
BuildOptions& add_method_options(BuildOptions& b, const MethodDesc& m, const FilterOptions& opt);
// The same as a string, without -cl-std.
std::string method_build_options(const MethodDesc& m, const FilterOptions& opt);
// The same and -DSF_LOOKUP=<opt.lookup.kind>: programs that read the basis through sf_lookup
// (the ESM classification, a caller's kernel from kernel_prelude()).
std::string method_lookup_build_options(const MethodDesc& m, const FilterOptions& opt);
// ScheduleOptions::reconstruct_vector_width, checked (1, 4, 8 or 16; InputError otherwise): the
// receivers per work-item of the reconstruction and the ESM classification's vector kernel.
int reconstruct_vector_width(const FilterOptions& opt);

}  // namespace sf::detail

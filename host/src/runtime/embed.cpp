#include "shadowfilter/embed.hpp"

#include <algorithm>

#include "embedded_kernels.hpp"
#include "method_build.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf {

KernelPrelude kernel_prelude(const FilterOptions& options) {
  const MethodDesc& m = *options.method;
  if (m.raw_depth)
    throw InputError("FilterOptions::method " + m.name +
                     " tests the depth map itself and has no basis to reconstruct from");
  m.validate(options);
  KernelPrelude p;
  p.files = {"shared_types.clh", "common.clh", "storage.clh", m.header, "lookup.clh"};
  for (const auto& f : p.files) p.source += kernel_source(f) + "\n";
  p.build_options = detail::method_lookup_build_options(m, options);
  p.params = m.pack_params(options);
  return p;
}

std::vector<std::string> kernel_files() {
  std::vector<std::string> names;
  for (const auto& k : detail::embedded_kernels()) names.emplace_back(k.path);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace sf

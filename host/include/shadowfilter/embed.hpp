#pragma once
// OpenCL C for a caller's own kernels (docs/embedding.md): a deferred-shading pass, say, that
// reads the basis a Pipeline filtered and reconstructs visibility itself.
//
// The kernel headers are installed under <prefix>/include/shadowfilter/cl/ (the CMake package's
// shadowfilter_KERNEL_INCLUDE_DIR is <prefix>/include). A caller's program includes them in
// this order, after the build options kernel_prelude() gives:
//   #include "shadowfilter/cl/shared_types.clh"  // parameter structs and constants
//   #include "shadowfilter/cl/common.clh"    // helpers
//   #include "shadowfilter/cl/storage.clh"   // sf_stored, sf_load (SF_STORAGE)
//   #include "shadowfilter/cl/methods/esm.clh"  // SF_CHANNELS, sf_method_params, sf_visibility
//   #include "shadowfilter/cl/lookup.clh"    // sf_lookup (SF_LOOKUP) and the other lookups
// and calls, per receiver (u, v in [0,1] of the map, d the receiver's light depth, f its
// footprint in texels):
//   float b[SF_CHANNELS];
//   sf_lookup(basis, chain, sat, width, height, u, v, f, b);
//   float vis = clamp(sf_visibility(b, clamp(d, 0.0f, 1.0f), params), 0.0f, 1.0f);
// with the buffers of Pipeline::lookup_tables() and `params` = kernel_prelude().params passed by
// value (clSetKernelArg with its size). Receivers outside [0,1]^2 or with a non-finite depth are
// lit: sf_receiver_outside() says which. The same files are embedded in the library, so
// kernel_prelude().source serves callers who build from strings instead of include paths.
#include <cstdint>
#include <string>
#include <vector>

#include "shadowfilter/options.hpp"

namespace sf {

struct KernelPrelude {
  // The header files in inclusion order, relative to include/shadowfilter/cl/.
  std::vector<std::string> files;
  // Their text concatenated in that order (no #include needed).
  std::string source;
  // Build options the headers need for these options: -DSF_METHOD_<name> -DSF_STORAGE=<n>
  // -DSF_LOOKUP=<n> and the method's own (e.g. -DSF_CSM_ORDER=8). OpenCL C 1.2 suffices; no
  // -cl-std is imposed. On a device without cl_khr_fp64 add nothing: the headers test for it.
  std::string build_options;
  // The bytes of the method's sf_method_params for these options, defaults resolved.
  std::vector<uint8_t> params;
};

// What a caller's kernel needs to reconstruct visibility from a basis filtered with `options`
// (its lookup kind decides SF_LOOKUP). Throws InputError for invalid options and for the
// raw-depth methods (sm, pcf), which have no basis to reconstruct from.
KernelPrelude kernel_prelude(const FilterOptions& options);

// Names of every embedded kernel file (e.g. "methods/esm.clh", "reconstruct.cl"), sorted; the
// text of each is kernel_source(name) (runtime.hpp).
std::vector<std::string> kernel_files();

}  // namespace sf

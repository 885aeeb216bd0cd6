#pragma once
#include <string>
#include <vector>

namespace sf::detail {
struct EmbeddedKernel {
  const char* path;  // relative to kernels/, e.g. "methods/esm.clh"
  const char* source;
};
const std::vector<EmbeddedKernel>& embedded_kernels();
// Whether `path` is one of the embedded files (runtime.cpp).
bool has_embedded_kernel(const std::string& path);
}  // namespace sf::detail

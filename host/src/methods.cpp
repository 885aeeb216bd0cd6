#include "shadowfilter/methods.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

#include "shadowfilter/errors.hpp"

namespace sf {
namespace {

// Largest ESM exponent whose centred storage exp(c (z - 1/2)) stays within normal float32
// numbers: exp(+-c/2) within [FLT_MIN, FLT_MAX] means c/2 <= 87.3.
constexpr float kEsmMaxCFloat32 = 174.0f;

template <typename T>
std::vector<uint8_t> bytes_of(const T& v) {
  std::vector<uint8_t> b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

MethodDesc esm_method() {
  MethodDesc m;
  m.name = "esm";
  m.summary = "exponential shadow maps: B = exp(c z), v = exp(-c d) bar(B)";
  m.header = "methods/esm.clh";
  m.channels = 1;
  m.parameters = "--esm-c C (default 80, float32 limit 174)";
  m.validate = [](const FilterOptions& o) {
    if (!std::isfinite(o.esm.c) || o.esm.c <= 0.0f)
      throw InputError("--esm-c must be a positive number, got " + std::to_string(o.esm.c));
    if (o.esm.c > kEsmMaxCFloat32) {
      std::ostringstream s;
      s << "--esm-c " << o.esm.c << " exceeds the float32 limit of " << kEsmMaxCFloat32
        << " (exp(c/2) must stay a normal float)";
      throw InputError(s.str());
    }
  };
  m.pack_params = [](const FilterOptions& o) {
    struct {
      float c;
    } p{o.esm.c};
    return bytes_of(p);
  };
  return m;
}

}  // namespace

const std::vector<MethodDesc>& methods() {
  static const std::vector<MethodDesc> all = {esm_method()};
  return all;
}

const MethodDesc& find_method(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : methods()) known += (known.empty() ? "" : ", ") + m.name;
  throw InputError("unknown method '" + name + "' (known: " + known + ")");
}

}  // namespace sf

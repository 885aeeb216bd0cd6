// The base device types' few functions (device_types.hpp).
#include "shadowfilter/device_types.hpp"

#include <algorithm>

namespace sf {

StageTimes& StageTimes::operator+=(const StageTimes& o) {
  upload += o.upload;
  transform += o.transform;
  blur += o.blur;
  pyramid += o.pyramid;
  sat += o.sat;
  zmax += o.zmax;
  reconstruct += o.reconstruct;
  classify += o.classify;
  project += o.project;
  blend += o.blend;
  download += o.download;
  resident += o.resident;
  return *this;
}

size_t BufferPlan::total() const {
  size_t t = 0;
  for (const auto& b : buffers) t += b.bytes;
  return t;
}

size_t BufferPlan::largest() const {
  size_t m = 0;
  for (const auto& b : buffers) m = std::max(m, b.bytes);
  return m;
}

size_t BufferPlan::bytes(const std::string& name) const {
  for (const auto& b : buffers)
    if (b.name == name) return b.bytes;
  return 0;
}

}  // namespace sf

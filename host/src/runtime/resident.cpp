// New buffers made resident before a frame runs in them (resident.hpp).
#include "resident.hpp"

#include "cl_errors.hpp"

namespace sf::detail {

cl::Event fault_in(Runtime& rt, std::initializer_list<const cl::Buffer*> buffers, cl::Event* first) try {
  cl::Event last;
  *first = cl::Event();
  if (rt.info().type != "CPU") return last;
  for (const cl::Buffer* b : buffers) {
    if (!b || !(*b)()) continue;
    rt.queue().enqueueFillBuffer(*b, cl_uchar(0), 0, b->getInfo<CL_MEM_SIZE>(), nullptr, &last);
    if (!(*first)()) *first = last;
  }
  return last;
} catch (const cl::Error& e) {
  throw_device_error("fault_in", e);
}

double resident_seconds(const cl::Event& first, const cl::Event& last) {
  return last() ? event_seconds(first, last) : 0.0;
}

}  // namespace sf::detail

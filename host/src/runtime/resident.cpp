// New buffers made resident before a frame runs in them (resident.hpp).
#include "resident.hpp"

#include "cl_errors.hpp"

namespace sf::detail {

PassEvents fault_in(Runtime& rt, std::initializer_list<const cl::Buffer*> buffers) try {
  PassEvents ev;
  if (rt.info().type != "CPU") return ev;
  for (const cl::Buffer* b : buffers) {
    if (!b || !(*b)()) continue;
    cl::Event e;
    rt.queue().enqueueFillBuffer(*b, cl_uchar(0), 0, b->getInfo<CL_MEM_SIZE>(), nullptr, &e);
    if (!ev.first()) ev.first = e;
    ev.last = e;
  }
  return ev;
} catch (const cl::Error& e) {
  throw_device_error("fault_in", e);
}

double resident_seconds(const PassEvents& ev) { return ev.last() ? event_seconds(ev.first, ev.last) : 0.0; }

}  // namespace sf::detail

#pragma once
// The first and last command of a call that enqueues several (pyramid, SAT, blur, the
// compression's scan): what the public enqueue_* functions return as `first` and their event.
#include "shadowfilter/opencl.hpp"

namespace sf::detail {

struct PassEvents {
  cl::Event first, last;
};

}  // namespace sf::detail

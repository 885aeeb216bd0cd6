#pragma once
// New buffers made resident before a frame runs in them (a one-shot run as fast as the bench).
// On a CPU device a buffer is host memory: its pages are faulted in, 4 KiB at a time, by the
// first command that touches them, inside that command's time. A new Pipeline's first frame
// paid that in every stage (backyard 2048^2, R = 3: transform 6.7-10 ms and blur 6.3-9.5 ms,
// against 1.6 and 1.6-2.7 ms with their buffers' pages in; docs/batch.md). fault_in() enqueues
// a fill of zeros over each new buffer on such a device, so that the stages run on resident
// pages; the fills are reported as StageTimes::resident, not as a stage. Where buffers are the
// device's own memory (a GPU) there is nothing to fault in and nothing is enqueued.
#include <initializer_list>

#include "shadowfilter/runtime.hpp"

namespace sf::detail {

// Fills every non-empty buffer of `buffers` (whole buffers, not sub-buffers) on a CPU device.
// As the enqueue_* functions: returns the last fill's event, `first` the first's; both empty
// when nothing was enqueued.
cl::Event fault_in(Runtime& rt, std::initializer_list<const cl::Buffer*> buffers, cl::Event* first);

// Seconds of fault_in()'s fills from `first` to `last` (0 when it enqueued none).
double resident_seconds(const cl::Event& first, const cl::Event& last);

}  // namespace sf::detail

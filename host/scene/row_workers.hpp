#pragma once
// Rows of an image spread over worker threads: each row is computed by exactly one call of
// row_fn, in whatever order, so an image whose pixels are independent comes out the same for
// any thread count.
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "progress.hpp"

namespace sf::scene {

// threads <= 0: hardware concurrency. progress: a bar on stderr (Progress) counting pixels.
template <class RowFn>
void for_each_row(const char* label, int rows, int width, int threads, bool progress, const RowFn& row_fn) {
  int workers = threads > 0 ? threads : int(std::thread::hardware_concurrency());
  workers = std::max(1, std::min(rows, workers));
  Progress bar(label, size_t(rows) * size_t(width), progress);
  std::atomic<int> next_row{0};
  auto work = [&] {
    for (int y = next_row++; y < rows; y = next_row++) {
      row_fn(y);
      bar.add(size_t(width));
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace sf::scene

#include "progress.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace sf::scene {

using Clock = std::chrono::steady_clock;

Progress::Progress(std::string label, size_t total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled), start_(Clock::now()), last_draw_(start_) {}

// A destructor never throws: a bar that cannot be drawn is left as it is.
Progress::~Progress() {
  try {
    if (shown_) draw(done_.load(), true);
  } catch (...) {
  }
}

void Progress::add(size_t done) {
  const size_t now_done = done_ += done;
  if (!enabled_) return;
  const auto now = Clock::now();
  if (now - start_ < std::chrono::seconds(1)) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(now_done, false);
}

// The bar, the count, the rate and the time left at that rate.
void Progress::draw(size_t done, bool final) {
  constexpr int kWidth = 40;
  // More done than announced (a search that went on longer) draws a full bar, not a negative gap.
  const double fraction = total_ ? std::min(1.0, double(done) / double(total_)) : 1.0;
  const int filled = int(fraction * kWidth + 0.5);
  const double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
  const double rate = seconds > 0 ? double(done) / seconds : 0.0;
  char eta[32] = "";
  if (!final && rate > 0 && done < total_)
    std::snprintf(eta, sizeof eta, ", %.0f s left", double(total_ - done) / rate);
  const std::string bar(filled, '#'), gap(kWidth - filled, ' ');
  std::string line(label_.size() + 160, '\0');
  const int n =
      std::snprintf(line.data(), line.size(), "\r  %-16s [%s%s] %3d%%  %zu/%zu  %.3g/s  %.1f s%s   ", label_.c_str(),
                    bar.c_str(), gap.c_str(), int(fraction * 100 + 0.5), done, total_, rate, seconds, eta);
  line.resize(n > 0 ? std::min(size_t(n), line.size() - 1) : 0);
  // std::cerr, not stderr: the CLI's in-process entry (host/cli/run.hpp) hands it the caller's stream.
  std::cerr << line << (final ? "\n" : "") << std::flush;
  shown_ = true;
}

}  // namespace sf::scene

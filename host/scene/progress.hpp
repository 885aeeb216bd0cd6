#pragma once
// A progress bar on stderr for long loops: silent for the first second, then a bar that is
// redrawn at most ten times a second; thread-safe (add() from any thread).
#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace sf::scene {

class Progress {
 public:
  Progress(std::string label, size_t total, bool enabled);
  ~Progress();  // finishes the line if a bar was shown
  void add(size_t done);

 private:
  void draw(size_t done, bool final);
  std::string label_;
  size_t total_;
  bool enabled_;
  std::atomic<size_t> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool shown_ = false;
};

}  // namespace sf::scene

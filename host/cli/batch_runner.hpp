#pragma once
// A batch of frames through three stages that overlap: decoding runs ahead on worker threads, processing (the device)
// runs on the calling thread, encoding runs one frame behind on another worker. What a stage throws as InputError fails
// its frame alone: with keep_going the batch reports it and goes on, without it the batch stops there, after the frames
// before it are written in full. Any other exception ends the batch (the frames before it still finish writing).
#include <chrono>
#include <algorithm>
#include <atomic>
#include <iostream>
#include <memory>
#include <deque>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "frame_list.hpp"
#include "interrupts.hpp"
#include "progress.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::cli {

struct BatchSettings {
  bool keep_going = false;  // --keep-going: report failed frames and carry on
  bool progress = false;    // a progress bar on stderr
  // Frames decoding at once ahead of the device: decoding is the longest stage of small frames
  // with their own receiver files (docs/batch.md), and where cores outnumber the stages a second
  // decoder keeps the device fed.
  size_t decode_ahead = 2;
};

struct BatchReport {
  size_t frames = 0, written = 0, failed = 0;
  // Seconds in each stage, summed over frames (decode and encode on their own threads), and the
  // batch's wall time.
  double decode = 0, process = 0, encode = 0, wall = 0;
};

template <class Loaded, class Done>
BatchReport run_batch(const std::vector<FrameSpec>& frames, const BatchSettings& settings,
                      const std::function<Loaded(const FrameSpec&)>& load,
                      const std::function<Done(const FrameSpec&, Loaded&)>& process,
                      const std::function<void(const FrameSpec&, const Done&)>& write) {
  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  const auto t0 = Clock::now();
  BatchReport report;
  report.frames = frames.size();
  std::optional<std::string> stop;  // the first failure, without keep_going
  auto failed = [&](const FrameSpec& frame, const char* what) {
    ++report.failed;
    const std::string message = frame.where + ": " + what;
    if (settings.keep_going)
      std::cerr << (settings.progress ? "\n" : "") << "shadowfilter: error: " << message << "\n";
    else if (!stop)
      stop = message;
  };
  scene::Progress bar("frames", frames.size(), settings.progress);
  // An interrupted batch says how far it got (interrupts.hpp): the frames written in full stay.
  auto written = std::make_shared<std::atomic<size_t>>(0);
  const InterruptReport interrupt_report([written, total = frames.size()] {
    return std::to_string(written->load()) + " of " + std::to_string(total) + " frames written";
  });

  auto start_load = [&](size_t i) {
    return std::async(std::launch::async, [&load, &frames, &seconds_since, i] {
      const auto t = Clock::now();
      Loaded loaded = load(frames[i]);
      return std::make_pair(std::move(loaded), seconds_since(t));
    });
  };
  std::deque<std::future<std::pair<Loaded, double>>> ahead;  // frames i, i + 1, ... decoding
  size_t started = 0;
  auto fill = [&] {
    while (!stop && started < frames.size() && ahead.size() < std::max<size_t>(settings.decode_ahead, 1))
      ahead.push_back(start_load(started++));
  };
  fill();
  std::future<double> writing;
  size_t writing_index = 0;
  auto finish_write = [&] {
    if (!writing.valid()) return;
    try {
      report.encode += writing.get();
      ++report.written;
      ++*written;
    } catch (const InputError& e) {
      failed(frames[writing_index], e.what());
    }
    bar.add(1);
  };

  for (size_t i = 0; i < frames.size() && !stop; ++i) {
    std::optional<std::pair<Loaded, double>> current;
    std::future<std::pair<Loaded, double>> next = std::move(ahead.front());
    ahead.pop_front();
    try {
      current.emplace(next.get());
      report.decode += current->second;
    } catch (const InputError& e) {
      failed(frames[i], e.what());
    }
    fill();
    std::optional<Done> done;
    if (current) {
      const auto t = Clock::now();
      try {
        done.emplace(process(frames[i], current->first));
      } catch (const InputError& e) {
        failed(frames[i], e.what());
      }
      report.process += seconds_since(t);
    }
    finish_write();  // the frame before this one
    if (!done) {
      bar.add(1);
      continue;
    }
    if (stop) break;  // the frame before failed to write: nothing after it is written
    writing_index = i;
    writing = std::async(std::launch::async, [&write, &frames, &seconds_since, i, d = std::move(*done)] {
      const auto t = Clock::now();
      write(frames[i], d);
      return seconds_since(t);
    });
  }
  finish_write();
  for (auto& f : ahead) f.wait();  // frames decoded ahead of a stop are dropped
  report.wall = seconds_since(t0);
  if (stop)
    throw InputError(*stop + " (batch stopped: " + std::to_string(report.written) + " frame" +
                     (report.written == 1 ? "" : "s") + " before it written; --keep-going skips failed frames)");
  return report;
}

}  // namespace sf::cli

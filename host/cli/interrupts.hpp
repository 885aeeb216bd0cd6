#pragma once
// SIGINT, SIGTERM and SIGHUP end a run cleanly: the temporary files and partial directories of
// unfinished outputs are removed (io::remove_unfinished_outputs_before_exit), one line says what happened
// (with a batch's progress), and the process exits with 128 + the signal (130, 143, 129).
// A signal that was ignored when the process started (nohup, a background job) stays ignored.
#include <functional>
#include <string>

namespace sf::cli {

// Blocks the signals in the calling thread and starts the thread that waits for them. Called
// first in main, before any other thread starts, so that every thread inherits the mask and only
// the watcher ever sees the signals.
void watch_interrupts();

// What an interrupted run says about its progress ("12 of 40 frames written"); called on the
// watcher thread, so it must read only atomics. An empty function clears it.
void set_interrupt_report(std::function<std::string()> report);

// set_interrupt_report for a scope.
class InterruptReport {
 public:
  explicit InterruptReport(std::function<std::string()> report) { set_interrupt_report(std::move(report)); }
  ~InterruptReport() { set_interrupt_report({}); }
  InterruptReport(const InterruptReport&) = delete;
  InterruptReport& operator=(const InterruptReport&) = delete;
};

}  // namespace sf::cli

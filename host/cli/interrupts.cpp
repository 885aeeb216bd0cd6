#include "interrupts.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>

#include "output_file.hpp"

namespace sf::cli {
namespace {

std::mutex report_mutex;
std::function<std::string()> progress_report;

bool ignored_at_start(int signal_number) {
  struct sigaction current {};
  return ::sigaction(signal_number, nullptr, &current) == 0 && current.sa_handler == SIG_IGN;
}

[[noreturn]] void end_interrupted(int signal_number) {
  std::string report;
  {
    std::lock_guard<std::mutex> lock(report_mutex);
    if (progress_report) report = progress_report();
  }
  const size_t removed = io::remove_unfinished_outputs_before_exit();
  std::fprintf(stderr, "\nshadowfilter: interrupted by %s%s%s; %zu unfinished output%s removed\n",
               signal_number == SIGINT    ? "SIGINT"
               : signal_number == SIGTERM ? "SIGTERM"
                                          : "SIGHUP",
               report.empty() ? "" : ": ", report.c_str(), removed, removed == 1 ? "" : "s");
  std::fflush(stderr);
  ::_exit(128 + signal_number);
}

}  // namespace

void watch_interrupts() {
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGINT, SIGTERM, SIGHUP})
    if (!ignored_at_start(s)) sigaddset(&signals, s);
  if (::pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) return;
  std::thread([signals] {
    for (;;) {
      int signal_number = 0;
      if (::sigwait(&signals, &signal_number) == 0) end_interrupted(signal_number);
    }
  }).detach();
}

void set_interrupt_report(std::function<std::string()> report) {
  std::lock_guard<std::mutex> lock(report_mutex);
  progress_report = std::move(report);
}

}  // namespace sf::cli

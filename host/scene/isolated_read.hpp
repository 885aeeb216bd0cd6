#pragma once
// A third-party parser run in a child process: whatever a hostile file does to it (a crash, an
// assertion that aborts, a loop that never ends), the command survives to say so in one line.
#include <functional>
#include <string>

namespace sf::scene {

struct IsolatedResult {
  enum class Kind { Done, Signalled, TimedOut, Failed } kind = Kind::Failed;
  std::string bytes;    // what `produce` returned (Done)
  int signal = 0;       // the signal that ended the child (Signalled)
  std::string failure;  // why the child could not run or report (Failed)
};

// Runs `produce` in a forked child and returns its bytes. The child catches nothing itself:
// `produce` must turn its own errors into bytes. A crash is reported as the signal (the child
// gives SIGSEGV, SIGBUS, SIGFPE and SIGILL their default action, so a sanitizer's handler does
// not turn them into an exit status), a child still running after `seconds` is killed, and a
// child that exits without its answer (a sanitizer report in our own code) is Failed.
IsolatedResult run_isolated(const std::function<std::string()>& produce, int seconds);

}  // namespace sf::scene

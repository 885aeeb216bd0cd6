#include "isolated_read.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace sf::scene {
namespace {

bool write_all(int fd, const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

[[noreturn]] void child(int fd, const std::function<std::string()>& produce) {
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL}) ::signal(s, SIG_DFL);
  // The answer ends with a marker, so that a child cut short is told from one that finished.
  const bool ok = write_all(fd, produce() + "\n.end");
  // _exit: no atexit handlers, static destructors or leak checks of the parent's state.
  ::_exit(ok ? 0 : 3);
}

}  // namespace

IsolatedResult run_isolated(const std::function<std::string()>& produce, int seconds) {
  IsolatedResult result;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    result.failure = std::string("cannot make a pipe: ") + std::strerror(errno);
    return result;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    result.failure = std::string("cannot start a process: ") + std::strerror(errno);
    ::close(fds[0]);
    ::close(fds[1]);
    return result;
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], produce);
  }
  ::close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  bool timed_out = false;
  char buffer[1 << 16];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left.count(), 1 << 30)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    result.bytes.append(buffer, size_t(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string marker = "\n.end";
  if (timed_out) {
    result.kind = IsolatedResult::Kind::TimedOut;
  } else if (WIFSIGNALED(status)) {
    result.kind = IsolatedResult::Kind::Signalled;
    result.signal = WTERMSIG(status);
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && result.bytes.size() >= marker.size() &&
             result.bytes.compare(result.bytes.size() - marker.size(), marker.size(), marker) == 0) {
    result.kind = IsolatedResult::Kind::Done;
    result.bytes.resize(result.bytes.size() - marker.size());
  } else {
    result.kind = IsolatedResult::Kind::Failed;
    result.failure = "the reading process exited with status " +
                     std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + " without its answer";
  }
  return result;
}

}  // namespace sf::scene

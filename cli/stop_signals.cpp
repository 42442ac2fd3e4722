// SPDX-License-Identifier: Apache-2.0
#include "cli/stop_signals.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>

namespace tensegrity::cli {

namespace {
// The one thing a signal handler can reach: the write end of the live guard's
// pipe (-1: none). Set and cleared by StopOnSignals only.
std::atomic<int> g_wake_fd{-1};
constexpr char kStop = 's';
constexpr char kQuit = 'q';

extern "C" void on_stop_signal(int) {
  const int saved = errno;
  const int fd = g_wake_fd.load();
  if (fd >= 0) (void)!::write(fd, &kStop, 1);
  errno = saved;
}
}  // namespace

StopOnSignals::StopOnSignals() {
  if (::pipe2(pipe_, O_CLOEXEC) != 0) return;  // no pipe: Ctrl-C keeps its default action
  watcher_ = std::thread([this] {
    char c = 0;
    for (;;) {
      const ssize_t n = ::read(pipe_[0], &c, 1);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0 || c == kQuit) return;
      source_.request_stop();
    }
  });
  g_wake_fd.store(pipe_[1]);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

StopOnSignals::~StopOnSignals() {
  if (!watcher_.joinable()) return;
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
  g_wake_fd.store(-1);
  (void)!::write(pipe_[1], &kQuit, 1);
  watcher_.join();
  ::close(pipe_[0]);
  ::close(pipe_[1]);
}

}  // namespace tensegrity::cli

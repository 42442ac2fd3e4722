// SPDX-License-Identifier: Apache-2.0
// SIGINT and SIGTERM as a std::stop_token while in scope: Ctrl-C ends a HIL run
// in order (the end caps shut down, the run directory removed) instead of
// killing the launcher. The handler only writes a byte to a pipe (all a handler
// may safely do); a watcher thread turns it into stop_source::request_stop().
// The previous handlers come back when it goes out of scope.
#pragma once

#include <csignal>
#include <stop_token>
#include <thread>

namespace tensegrity::cli {

class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

  std::stop_token token() const { return source_.get_token(); }

 private:
  std::stop_source source_;
  int pipe_[2] = {-1, -1};
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
  std::thread watcher_;
};

}  // namespace tensegrity::cli

// SPDX-License-Identifier: Apache-2.0
// The operator console's keys: single key presses on a terminal (raw mode, the
// terminal's settings restored on exit), or lines from a pipe (their first
// letter), so a script or a test drives the console as a person does.
#pragma once

#include <termios.h>

#include <chrono>
#include <string>

namespace tensegrity::cli {

enum class ConsoleKey { none, estop, stop, clear_fault, quit };

// e or space: emergency stop; s: stop; c: clear fault; q: quit.
ConsoleKey key_of(char c);

class ConsoleKeys {
 public:
  ConsoleKeys();
  ~ConsoleKeys();
  ConsoleKeys(const ConsoleKeys&) = delete;
  ConsoleKeys& operator=(const ConsoleKeys&) = delete;

  // The next key within `timeout`, else none (also once stdin has ended).
  ConsoleKey next(std::chrono::milliseconds timeout);
  bool terminal() const { return terminal_; }

 private:
  bool terminal_ = false;
  bool ended_ = false;
  termios saved_{};
  std::string line_;
};

}  // namespace tensegrity::cli

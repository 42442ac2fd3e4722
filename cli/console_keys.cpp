// SPDX-License-Identifier: Apache-2.0
#include "cli/console_keys.hpp"

#include <poll.h>
#include <unistd.h>

#include <thread>

namespace tensegrity::cli {

ConsoleKey key_of(char c) {
  switch (c) {
    case 'e':
    case 'E':
    case ' ': return ConsoleKey::estop;
    case 's':
    case 'S': return ConsoleKey::stop;
    case 'c':
    case 'C': return ConsoleKey::clear_fault;
    case 'q':
    case 'Q': return ConsoleKey::quit;
    default: return ConsoleKey::none;
  }
}

ConsoleKeys::ConsoleKeys() {
  terminal_ = ::isatty(STDIN_FILENO) == 1 && ::tcgetattr(STDIN_FILENO, &saved_) == 0;
  if (!terminal_) return;
  termios raw = saved_;
  raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));  // keys without Enter; Ctrl-C still a signal
  raw.c_cc[VMIN] = 1;
  raw.c_cc[VTIME] = 0;
  ::tcsetattr(STDIN_FILENO, TCSANOW, &raw);
}

ConsoleKeys::~ConsoleKeys() {
  if (terminal_) ::tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
}

ConsoleKey ConsoleKeys::next(std::chrono::milliseconds timeout) {
  if (ended_) {
    std::this_thread::sleep_for(timeout);
    return ConsoleKey::none;
  }
  pollfd p{STDIN_FILENO, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return ConsoleKey::none;
  char c = 0;
  if (::read(STDIN_FILENO, &c, 1) != 1) {
    ended_ = true;  // stdin closed: the console goes on serving its socket
    return ConsoleKey::none;
  }
  if (terminal_) return key_of(c);
  if (c != '\n') {
    if (line_.size() < 256) line_.push_back(c);  // only the first letter counts
    return ConsoleKey::none;
  }
  const std::size_t first = line_.find_first_not_of(" \t");
  const ConsoleKey key = first == std::string::npos ? ConsoleKey::none : key_of(line_[first]);
  line_.clear();
  return key;
}

}  // namespace tensegrity::cli

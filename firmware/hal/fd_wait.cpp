// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/fd_wait.hpp"

#include <poll.h>

#include <cerrno>
#include <ctime>

#include "firmware/hal/clock.hpp"

namespace tensegrity::fw::detail {
namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;
}

std::int64_t receive_deadline_ns(std::int64_t timeout_ns) {
  if (timeout_ns < 0) return -1;
  return SystemClock().now_ns() + timeout_ns;
}

WaitResult wait_readable(int fd, std::int64_t deadline_ns) {
  for (;;) {
    pollfd pfd{fd, POLLIN, 0};
    timespec ts{};
    timespec* tsp = nullptr;
    if (deadline_ns >= 0) {
      std::int64_t remaining_ns = deadline_ns - SystemClock().now_ns();
      if (remaining_ns < 0) remaining_ns = 0;
      ts.tv_sec = static_cast<time_t>(remaining_ns / kNsPerS);
      ts.tv_nsec = static_cast<long>(remaining_ns % kNsPerS);
      tsp = &ts;
    }
    // ppoll rather than poll: poll's millisecond timeout would round a 1 kHz
    // loop's sub-millisecond waits to zero or to a whole period.
    const int rc = ::ppoll(&pfd, 1, tsp, nullptr);
    if (rc > 0) return (pfd.revents & (POLLERR | POLLNVAL)) != 0 ? WaitResult::error : WaitResult::ready;
    if (rc == 0) return WaitResult::timeout;
    if (errno != EINTR) return WaitResult::error;
  }
}

bool send_error_is_transient(int error_number) {
  return error_number == EAGAIN || error_number == EWOULDBLOCK || error_number == ENOBUFS;
}

}  // namespace tensegrity::fw::detail

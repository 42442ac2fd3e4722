// SPDX-License-Identifier: Apache-2.0
// Waiting on a non-blocking socket with a nanosecond deadline; shared by the
// UDP and SocketCAN backends.
#pragma once

#include <cstdint>

namespace tensegrity::fw::detail {

enum class WaitResult : std::uint8_t { ready, timeout, error };

// Deadline for receive(timeout_ns): -1 = none (wait forever).
std::int64_t receive_deadline_ns(std::int64_t timeout_ns);
// Waits until `fd` is readable or CLOCK_MONOTONIC passes `deadline_ns`.
WaitResult wait_readable(int fd, std::int64_t deadline_ns);

// What a failed send's errno means to the caller: a full transmit queue (EAGAIN,
// EWOULDBLOCK, or ENOBUFS as a full CAN queue shows itself) is `would_block`,
// anything else `io_error`.
bool send_error_is_transient(int error_number);

}  // namespace tensegrity::fw::detail

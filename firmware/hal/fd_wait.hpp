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

}  // namespace tensegrity::fw::detail

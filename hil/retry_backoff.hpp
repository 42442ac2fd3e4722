// SPDX-License-Identifier: Apache-2.0
// How often the HIL's supervisor asks a restarted end cap again after it refused
// an order (or did not answer). A refusal is acknowledged at once, so without a
// wait an end cap that keeps refusing would get the order at every supervisor
// tick (50 Hz) with a log line each. The wait doubles from first_wait_ns up to
// max_wait_ns; the log keeps the 1st, 2nd, 4th, 8th ... refusal, and one whose
// reason differs from the last, with the count.
// One per end cap, keyed by the restart it belongs to: a new restart starts afresh.
#pragma once

#include <cstdint>
#include <string>

namespace tensegrity::hil {

class RetryBackoff {
 public:
  static constexpr std::int64_t kFirstWaitNs = 250'000'000;
  static constexpr std::int64_t kMaxWaitNs = 2'000'000'000;

  explicit RetryBackoff(std::int64_t first_wait_ns = kFirstWaitNs, std::int64_t max_wait_ns = kMaxWaitNs);

  // Forgets the count and the wait if `restart_ns` is not the restart it counted for.
  void follow(std::int64_t restart_ns);
  // Whether an order may be sent at `now_ns`.
  bool due(std::int64_t now_ns) const { return now_ns >= next_try_ns_; }
  // One refusal at `now_ns`, with the end cap's reason: the next try waits. True if
  // this one deserves a log line.
  bool refused(std::int64_t now_ns, std::string reason);
  std::int64_t restart_ns() const { return restart_ns_; }
  int refusals() const { return refusals_; }
  const std::string& last_reason() const { return last_reason_; }
  std::int64_t wait_ns() const { return wait_ns_; }

 private:
  std::int64_t first_wait_ns_;
  std::int64_t max_wait_ns_;
  std::int64_t restart_ns_ = 0;
  std::int64_t next_try_ns_ = 0;
  std::int64_t wait_ns_ = 0;
  int refusals_ = 0;
  std::string last_reason_;
};

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
#include "hil/retry_backoff.hpp"

#include <algorithm>
#include <utility>

namespace tensegrity::hil {

RetryBackoff::RetryBackoff(std::int64_t first_wait_ns, std::int64_t max_wait_ns)
    : first_wait_ns_(std::max<std::int64_t>(first_wait_ns, 0)), max_wait_ns_(std::max(max_wait_ns, first_wait_ns_)) {}

void RetryBackoff::follow(std::int64_t restart_ns) {
  if (restart_ns == restart_ns_) return;
  restart_ns_ = restart_ns;
  next_try_ns_ = 0;
  wait_ns_ = 0;
  refusals_ = 0;
  last_reason_.clear();
}

bool RetryBackoff::refused(std::int64_t now_ns, std::string reason) {
  ++refusals_;
  const bool new_reason = reason != last_reason_;
  last_reason_ = std::move(reason);
  wait_ns_ = wait_ns_ == 0 ? first_wait_ns_ : std::min(2 * wait_ns_, max_wait_ns_);
  next_try_ns_ = now_ns + wait_ns_;
  // Powers of two: a handful of lines however long it goes on, the first one at once;
  // and a reason that changed, which is news.
  return new_reason || (refusals_ & (refusals_ - 1)) == 0;
}

}  // namespace tensegrity::hil

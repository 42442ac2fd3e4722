// SPDX-License-Identifier: Apache-2.0
#include "hil/answer_nap.hpp"

#include <algorithm>

namespace tensegrity::hil {

std::int64_t AnswerNap::nap_ns() const {
  return std::min(kMaxNapNs, static_cast<std::int64_t>(fraction_ * smoothed_ns_));
}

void AnswerNap::observe(std::int64_t latency_ns) {
  if (latency_ns <= 0) return;
  // One slow tick (a preempted end cap) must not stretch the naps that follow:
  // a sample counts for at most twice the current estimate.
  const double sample = smoothed_ns_ > 0.0 ? std::min(static_cast<double>(latency_ns), 2.0 * smoothed_ns_)
                                           : static_cast<double>(latency_ns);
  smoothed_ns_ = smoothed_ns_ > 0.0 ? (1.0 - kSmoothing) * smoothed_ns_ + kSmoothing * sample : sample;
}

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/loop_watch.hpp"

#include <cmath>

namespace tensegrity::fw::comms {

LoopWatch::LoopWatch(const std::atomic<std::uint64_t>* progress, double stall_timeout_s, const NodeLog& log)
    : progress_(progress), stall_timeout_ns_(std::llround(stall_timeout_s * 1e9)), log_(log) {}

bool LoopWatch::alive(std::int64_t now_ns) {
  if (progress_ == nullptr) return true;
  const std::uint64_t progress = progress_->load(std::memory_order_relaxed);
  if (progress != progress_seen_) {
    progress_seen_ = progress;
    progress_ns_ = now_ns;
  }
  // Armed by the loop's first pass: the program starts its node before its loop.
  if (progress == 0) return true;
  const bool stalled = now_ns - progress_ns_ > stall_timeout_ns_;
  if (stalled != stalled_) {
    if (stalled) stalls_.fetch_add(1, std::memory_order_relaxed);
    log_("control loop %s", stalled ? "STALLED: DDS heartbeat withheld" : "progressing again: DDS heartbeat resumed");
  }
  stalled_ = stalled;
  return !stalled;
}

bool LinkFaultWatch::poll() {
  if (link_cut_ != nullptr) {
    const bool cut = link_cut_->load(std::memory_order_relaxed);
    if (cut != was_cut_) {
      was_cut_ = cut;
      if (cut) cuts_.fetch_add(1, std::memory_order_relaxed);
      log_("DDS link %s (fault injection)", cut ? "CUT" : "restored");
    }
  }
  if (mute_requests_ == nullptr) return false;
  const std::uint32_t requests = mute_requests_->load(std::memory_order_relaxed);
  if (requests == mutes_seen_) return false;
  mutes_seen_ = requests;
  log_("DDS participant MUTED (fault injection): it hears the host, nothing it sends arrives");
  return true;
}

}  // namespace tensegrity::fw::comms

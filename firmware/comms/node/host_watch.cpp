// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/host_watch.hpp"

#include <cmath>

namespace tensegrity::fw::comms {

HostWatch::HostWatch(double timeout_s, double boot_grace_s, HostLossAction action, std::uint16_t format_version,
                     const NodeLog& log)
    : timeout_ns_(std::llround(timeout_s * 1e9)),
      boot_grace_ns_(std::llround(boot_grace_s * 1e9)),
      action_(action),
      format_version_(format_version),
      log_(log) {}

bool HostWatch::accepts(std::uint16_t format_version) {
  if (format_version == format_version_) return true;
  if (refused_format_++ % 100 == 0) {
    log_("REFUSED host heartbeat: format version %u, this end cap speaks %u", unsigned{format_version},
         unsigned{format_version_});
  }
  return false;
}

void HostWatch::heard(std::int64_t now_ns) {
  last_heard_ns_ = now_ns;
  seen_ = true;
}

// Armed from the node's start: before any host was heard, the boot grace is the wait.
bool HostWatch::poll(std::int64_t now_ns) {
  const std::int64_t silent_since = seen_ ? last_heard_ns_ : started_ns_;
  const bool lost = now_ns - silent_since > (seen_ ? timeout_ns_ : boot_grace_ns_);
  // While the host stays lost the stop is asked again at every check, not only when
  // it went: a start taken meanwhile (from a tool that sends no heartbeat, say) must
  // not leave the end cap playing unwatched. The loop latches only while playing.
  if (lost && lost_ && action_ == HostLossAction::stop) stops_.fetch_add(1, std::memory_order_acq_rel);
  if (lost == lost_) return false;
  lost_ = lost;
  (lost ? losses_ : returns_).fetch_add(1, std::memory_order_relaxed);
  log_("host %s (configured action: %s)",
       lost ? (seen_ ? "LOST: no heartbeat" : "LOST: none heard since start") : "back", to_string(action_));
  if (lost && action_ == HostLossAction::stop) stops_.fetch_add(1, std::memory_order_acq_rel);
  return lost;
}

}  // namespace tensegrity::fw::comms

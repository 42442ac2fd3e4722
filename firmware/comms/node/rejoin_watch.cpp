// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/rejoin_watch.hpp"

#include <algorithm>
#include <cmath>

#include "msgs/security.hpp"

namespace tensegrity::fw::comms {

namespace {
constexpr std::uint16_t kRobotsEndcaps = (1U << msgs::kMaxEndcaps) - 1;
std::int64_t to_ns(double s) { return std::llround(s * 1e9); }
}  // namespace

RejoinWatch::RejoinWatch(int endcap_id, double unheard_rejoin_s, const NodeLog& log)
    : self_bit_(static_cast<std::uint16_t>(1U << endcap_id)), unheard_rejoin_s_(unheard_rejoin_s), log_(log) {}

void RejoinWatch::start(std::int64_t now_ns) {
  participant_since_ns_ = now_ns;
  wait_s_ = unheard_rejoin_s_;
}

void RejoinWatch::heard(std::uint16_t heard_endcaps, std::int64_t now, bool fresh_host, bool on_current) {
  heard_endcaps &= kRobotsEndcaps;  // bits of end caps the robot does not have mean nothing
  // A host heard again after a loss (or for the first time) gets a full wait to hear
  // us, and the first one: the back-off answered a host that never heard us, and a
  // host that came back (restarted, or another one) is not known to be that host.
  if (fresh_host) {
    hearing_since_ns_ = now;
    wait_s_ = unheard_rejoin_s_;
  }
  if ((heard_endcaps & self_bit_) != 0) {
    // Named once the old participant's last heartbeats have left the host's window:
    // the new one is heard, the rejoin answered.
    if (now - participant_since_ns_ > kHostWindowNs && named_ns_ - participant_since_ns_ <= kHostWindowNs) {
      wait_s_ = unheard_rejoin_s_;
    }
    named_ns_ = now;
  }
  // The evidence against this end cap starts when hosts begin to hear others.
  if ((heard_endcaps & ~self_bit_) != 0) {
    if (now - others_named_ns_ > kHostWindowNs) others_named_since_ns_ = now;
    others_named_ns_ = now;
  }
  if (on_current) current_hears_host_ = true;  // after a rejoin: the new one hears too
}

RejoinWatch::Step RejoinWatch::poll(std::int64_t now, const Host& host, bool overlapping) {
  Step step;
  // The old participant goes once the link works both ways on the new one: a host
  // names it, and it has taken a host heartbeat itself.
  if (overlapping && named_ns_ - participant_since_ns_ > kHostWindowNs && current_hears_host_) {
    step.retire_old = true;
    log_("a host hears the new DDS participant and it hears the host: the old one closed");
  }
  const bool off = unheard_rejoin_s_ == 0.0;
  if (off || !host.seen || host.lost || host.loop_stalled || now - named_ns_ < kHostWindowNs) {
    remake_pending_ = false;  // whatever asked for a new participant holds no more
    remake_failures_ = 0;
  }
  if (remake_pending_) {
    step.rejoin = now >= next_remake_ns_;
    return step;
  }
  if (off || !host.seen || host.lost) return step;
  // A stalled loop withholds the heartbeat on purpose: no host can name us then,
  // and a new participant would not change that. The wait starts again after it.
  if (host.loop_stalled) {
    hearing_since_ns_ = now;
    return step;
  }
  if (now - others_named_ns_ > kHostWindowNs) return step;
  const std::int64_t since = std::max({named_ns_, hearing_since_ns_, others_named_since_ns_, participant_since_ns_});
  if (now - since < to_ns(wait_s_)) return step;
  step.rejoin = rejoin_unheard("hearing the host, which hears other end caps, but not heard by it", now - since, "");
  return step;
}

// Both ways of finding this end cap unheard: said, and the next wait doubled.
bool RejoinWatch::rejoin_unheard(const char* what, std::int64_t unheard_ns, const char* then) {
  log_("%s for %.0f s%s: a new DDS participant (rejoin %llu)", what, static_cast<double>(unheard_ns) * 1e-9, then,
       static_cast<unsigned long long>(rejoins_.load(std::memory_order_relaxed) + 1));
  wait_s_ = std::min(2.0 * wait_s_, kMaxBackoff * unheard_rejoin_s_);
  return true;
}

// A host that stops hearing an end cap's participant drops it when its lease runs
// out (Fast DDS's default: 20 s, as long as the default wait) and sends it nothing
// more: the end cap then loses the host, and a lost host is no evidence, so the wait
// in poll() never ends. If the host's last heartbeats named other end caps but not
// this one for longer than its window, the loss is this participant's doing: a new
// one is announced afresh and found again (seen with a participant muted one way,
// tests/hil/hil_dds_test.cpp). A host that dies while it hears this end cap names it
// to the end, and the end cap only waits for it.
bool RejoinWatch::host_lost(std::int64_t last, bool loop_stalled) {
  if (unheard_rejoin_s_ == 0.0 || loop_stalled) return false;
  if (last - named_ns_ <= kHostWindowNs || last - others_named_ns_ > kHostWindowNs) return false;
  if (last - participant_since_ns_ <= kHostWindowNs) return false;  // too new to have been judged
  return rejoin_unheard("host lost after it heard other end caps but not this one", last - named_ns_,
                        "; it dropped this participant");
}

void RejoinWatch::made(std::int64_t made_ns) {
  if (remake_failures_ > 0) log_("made a new DDS participant after %u failed attempts", remake_failures_);
  remake_pending_ = false;
  remake_failures_ = 0;
  current_hears_host_ = false;
  rejoins_.fetch_add(1, std::memory_order_relaxed);
  // Counted from when it exists: a secured participant takes a second or more to make.
  participant_since_ns_ = made_ns;
}

// Retried while the reason for it holds, less often each time (a missing
// certificate does not come back in a second; a secured try blocks the node thread).
void RejoinWatch::failed(std::int64_t now_ns, const char* what) {
  remake_retry_ns_ = remake_pending_ ? std::min(2 * remake_retry_ns_, kRemakeRetryMaxNs) : kRemakeRetryNs;
  log_("cannot make a new DDS participant: %s; the old one stays, trying again in %.0f s", what,
       static_cast<double>(remake_retry_ns_) * 1e-9);
  remake_pending_ = true;
  ++remake_failures_;
  next_remake_ns_ = now_ns + remake_retry_ns_;  // from the end of an attempt that took a while
}

}  // namespace tensegrity::fw::comms

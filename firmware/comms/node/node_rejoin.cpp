// SPDX-License-Identifier: Apache-2.0
// The end cap's side of a stalled link. Fast DDS 2.9's security handshake now and
// then stalls for good in one direction (docs/guide/security.md): an end cap then hears
// the host's heartbeat while the host never hears its own, and no new host
// participant clears it. The host's heartbeat names the end caps it hears; an end
// cap that hears hosts which hear other end caps but not itself, for
// unheard_rejoin_s, makes a new participant, as the host's stations do on their
// side (ground/station_keeper.hpp). A host that hears nobody is left to mend its
// own side: the fault is then not this end cap's to fix, and a one-shot tool that
// has not heard anyone yet must not make twelve end caps churn.
#include <algorithm>
#include <cmath>
#include <exception>

#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "msgs/security.hpp"

namespace tensegrity::fw::comms {

namespace {
constexpr double kMaxBackoff = 8.0;                         // the wait grows to at most 8 x unheard_rejoin_s
constexpr std::int64_t kHostWindowNs = 2'000'000'000;       // a host's heard mask covers its last 2 s
constexpr std::int64_t kRemakeRetryNs = 1'000'000'000;      // making a participant failed: try again after,
constexpr std::int64_t kRemakeRetryMaxNs = 60'000'000'000;  // doubling up to this
constexpr std::uint16_t kRobotsEndcaps = (1U << msgs::kMaxEndcaps) - 1;
std::int64_t to_ns(double s) { return std::llround(s * 1e9); }
}  // namespace

void EndcapNode::note_host_heartbeat(std::uint16_t heard_endcaps, std::int64_t now) {
  heard_endcaps &= kRobotsEndcaps;  // bits of end caps the robot does not have mean nothing
  // A host heard again after a loss (or for the first time) gets a full wait to hear
  // us, and the first one: the back-off answered a host that never heard us, and a
  // host that came back (restarted, or another one) is not known to be that host.
  if (!host_seen_ || host_lost_.load()) {
    hearing_since_ns_ = now;
    rejoin_wait_s_ = config_.unheard_rejoin_s;
  }
  if ((heard_endcaps & (1U << config_.endcap_id)) != 0) {
    // Named once the old participant's last heartbeats have left the host's window:
    // the new one is heard, the rejoin answered.
    if (now - participant_since_ns_ > kHostWindowNs && named_ns_ - participant_since_ns_ <= kHostWindowNs) {
      rejoin_wait_s_ = config_.unheard_rejoin_s;
    }
    named_ns_ = now;
  }
  // The evidence against this end cap starts when hosts begin to hear others.
  if ((heard_endcaps & ~(1U << config_.endcap_id)) != 0) {
    if (now - others_named_ns_ > kHostWindowNs) others_named_since_ns_ = now;
    others_named_ns_ = now;
  }
}

void EndcapNode::check_heard(std::int64_t now) {
  // The old participant goes once the link works both ways on the new one: a host
  // names it, and it has taken a host heartbeat itself.
  if (retiring_ != nullptr && named_ns_ - participant_since_ns_ > kHostWindowNs && current_hears_host_) {
    retire();
    log("a host hears the new DDS participant and it hears the host: the old one closed");
  }
  if (config_.unheard_rejoin_s == 0.0 || !host_seen_ || host_lost_.load() || loop_stall_reported_ ||
      now - named_ns_ < kHostWindowNs) {
    remake_pending_ = false;  // whatever asked for a new participant holds no more
    remake_failures_ = 0;
  }
  if (remake_pending_) {
    if (now >= next_remake_ns_) rejoin();
    return;
  }
  if (config_.unheard_rejoin_s == 0.0 || !host_seen_ || host_lost_.load()) return;
  // A stalled loop withholds the heartbeat on purpose: no host can name us then,
  // and a new participant would not change that. The wait starts again after it.
  if (loop_stall_reported_) {
    hearing_since_ns_ = now;
    return;
  }
  if (now - others_named_ns_ > kHostWindowNs) return;
  const std::int64_t since = std::max({named_ns_, hearing_since_ns_, others_named_since_ns_, participant_since_ns_});
  if (now - since < to_ns(rejoin_wait_s_)) return;
  rejoin_unheard("hearing the host, which hears other end caps, but not heard by it", now - since, "");
}

// Both ways of finding this end cap unheard: said, and the next wait doubled.
void EndcapNode::rejoin_unheard(const char* what, std::int64_t unheard_ns, const char* then) {
  log("%s for %.0f s%s: a new DDS participant (rejoin %llu)", what, static_cast<double>(unheard_ns) * 1e-9, then,
      static_cast<unsigned long long>(rejoins_.load(std::memory_order_relaxed) + 1));
  rejoin_wait_s_ = std::min(2.0 * rejoin_wait_s_, kMaxBackoff * config_.unheard_rejoin_s);
  rejoin();
}

// A host that stops hearing an end cap's participant drops it when its lease runs
// out (Fast DDS's default: 20 s, as long as the default wait above) and sends it
// nothing more: the end cap then loses the host, and a lost host is no evidence, so
// the wait above never ends. If the host's last heartbeats named other end caps but
// not this one for longer than its window, the loss is this participant's doing: a
// new one is announced afresh and found again (seen with a participant muted one way,
// tests/hil/hil_dds_test.cpp). A host that dies while it hears this end cap names it
// to the end, and the end cap only waits for it.
void EndcapNode::note_host_lost() {
  if (config_.unheard_rejoin_s == 0.0 || loop_stall_reported_) return;
  const std::int64_t last = last_host_heartbeat_ns_;
  if (last - named_ns_ <= kHostWindowNs || last - others_named_ns_ > kHostWindowNs) return;
  if (last - participant_since_ns_ <= kHostWindowNs) return;  // too new to have been judged
  rejoin_unheard("host lost after it heard other end caps but not this one", last - named_ns_,
                 "; it dropped this participant");
}

// On the node thread, the only one that uses dds_. The new participant is made
// before the old one goes: the stall may be one way only, so the old one can still
// carry orders in (an emergency stop among them) until the link works both ways on
// the new one, and it stays for good if a new one cannot be made. The two
// participants' command listeners take turns (receive_mutex_), each acking on both
// participants (which one the host hears is not known); telemetry and heartbeats go
// out on the new one only.
void EndcapNode::rejoin() {
  std::unique_ptr<Dds> fresh;
  try {
    fresh = make_dds();
  } catch (const std::exception& e) {
    // Retried while the reason for it holds, less often each time (a missing
    // certificate does not come back in a second; a secured try blocks this thread).
    remake_retry_ns_ = remake_pending_ ? std::min(2 * remake_retry_ns_, kRemakeRetryMaxNs) : kRemakeRetryNs;
    log("cannot make a new DDS participant: %s; the old one stays, trying again in %.0f s", e.what(),
        static_cast<double>(remake_retry_ns_) * 1e-9);
    remake_pending_ = true;
    ++remake_failures_;
    next_remake_ns_ = clock_.now_ns() + remake_retry_ns_;  // from the end of an attempt that took a while
    return;
  }
  if (remake_failures_ > 0) log("made a new DDS participant after %u failed attempts", remake_failures_);
  remake_pending_ = false;
  remake_failures_ = 0;
  retire();  // an older one still listening: never more than two
  retiring_ = std::move(dds_);
  {
    std::lock_guard lock(retiring_->callback_mutex);
    retiring_->retiring = true;
  }
  dds_ = std::move(fresh);
  pair_participants(true);
  current_hears_host_ = false;
  rejoins_.fetch_add(1, std::memory_order_relaxed);
  // Counted from when it exists: a secured participant takes a second or more to make.
  const std::int64_t made = clock_.now_ns();
  participant_since_ns_ = made;
  // Send at once on the new participant; a table half way to the loop is acked from it.
  next_telemetry_ns_ = next_heartbeat_ns_ = next_sync_ns_ = made;
}

void EndcapNode::pair_participants(bool paired) noexcept {
  std::lock_guard serial(receive_mutex_);  // no command listener is between its two acks
  if (dds_ != nullptr) dds_->peer = paired ? retiring_.get() : nullptr;
  if (retiring_ != nullptr) retiring_->peer = paired ? dds_.get() : nullptr;
}

void EndcapNode::retire() noexcept {
  if (retiring_ == nullptr) return;
  pair_participants(false);
  retiring_->close();  // its listeners finish and are refused from then on
  retiring_.reset();
}

}  // namespace tensegrity::fw::comms

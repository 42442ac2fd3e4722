// SPDX-License-Identifier: Apache-2.0
// What the node says about the end cap (telemetry, heartbeat) and what it watches
// of the host (its heartbeat: host loss) and of the link (fault injection).
#include <array>
#include <cmath>

#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "tensegrity_msgs/msg/Heartbeat.h"
#include "tensegrity_msgs/msg/Telemetry.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

void EndcapNode::handle_host_heartbeats(Dds& d, std::int64_t now) {
  m::Heartbeat_ hb;
  dds::SampleInfo info;
  while (d.host_heartbeat->take_next_sample(&hb, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (hb.format_version() != msgs::kFormatVersion) {
      if (refused_format_++ % 100 == 0) {
        log("REFUSED host heartbeat: format version %u, this end cap speaks %u", unsigned{hb.format_version()},
            unsigned{msgs::kFormatVersion});
      }
      continue;
    }
    note_host_heartbeat(hb.heard_endcaps(), now);
    last_host_heartbeat_ns_ = now;
    host_seen_ = true;
    if (&d == dds_.get()) current_hears_host_ = true;  // after a rejoin: the new one hears too
  }
}

// The flag is flipped from outside (a signal handler): said here, on the node's
// thread, so the log shows when the link went and came back.
void EndcapNode::report_link_cut() {
  if (config_.link_cut == nullptr) return;
  const bool cut = config_.link_cut->load(std::memory_order_relaxed);
  if (cut == link_was_cut_) return;
  link_was_cut_ = cut;
  if (cut) link_cuts_.fetch_add(1, std::memory_order_relaxed);
  log("DDS link %s (fault injection)", cut ? "CUT" : "restored");
}

// Only the participant of the moment is muted: the fault is a stalled handshake,
// which belongs to a participant, not to the link.
void EndcapNode::apply_mute_fault() {
  if (config_.mute_requests == nullptr) return;
  const std::uint32_t requests = config_.mute_requests->load(std::memory_order_relaxed);
  if (requests == mutes_seen_) return;
  mutes_seen_ = requests;
  dds_->muted.store(true, std::memory_order_relaxed);
  log("DDS participant MUTED (fault injection): it hears the host, nothing it sends arrives");
}

// Armed from the node's start: before any host was heard, the boot grace is the wait.
void EndcapNode::check_host_loss(std::int64_t now) {
  const std::int64_t silent_since = host_seen_ ? last_host_heartbeat_ns_ : started_ns_;
  const double limit_s = host_seen_ ? config_.host_timeout_s : config_.host_boot_grace_s;
  const bool lost = now - silent_since > std::llround(limit_s * 1e9);
  // While the host stays lost the stop is asked again at every check, not only when
  // it went: a start taken meanwhile (from a tool that sends no heartbeat, say) must
  // not leave the end cap playing unwatched. The loop latches only while playing.
  if (lost && lost == host_lost_.load() && config_.host_loss == HostLossAction::stop) {
    host_loss_stops_.fetch_add(1, std::memory_order_acq_rel);
  }
  if (lost == host_lost_.load()) return;
  host_lost_.store(lost);
  (lost ? host_losses_ : host_returns_).fetch_add(1, std::memory_order_relaxed);
  log("host %s (configured action: %s)",
      lost ? (host_seen_ ? "LOST: no heartbeat" : "LOST: none heard since start") : "back",
      to_string(config_.host_loss));
  // A counter the loop reads every cycle, like the estop: never refused by a full mailbox.
  if (lost && config_.host_loss == HostLossAction::stop) host_loss_stops_.fetch_add(1, std::memory_order_acq_rel);
  if (lost) note_host_lost();  // perhaps our own doing (node_rejoin.cpp)
}

// The one place that decides whether the control loop is alive, for the heartbeat:
// the loop-progress watchdog. A hung loop must look dead to the host.
bool EndcapNode::loop_alive(std::int64_t now) {
  if (config_.loop_progress == nullptr) return true;
  const std::uint64_t progress = config_.loop_progress->load(std::memory_order_relaxed);
  if (progress != loop_progress_seen_) {
    loop_progress_seen_ = progress;
    loop_progress_ns_ = now;
  }
  // Armed by the loop's first pass: the program starts its node before its loop.
  if (progress == 0) return true;
  const bool stalled = now - loop_progress_ns_ > std::llround(config_.loop_stall_timeout_s * 1e9);
  if (stalled != loop_stall_reported_) {
    if (stalled) loop_stalls_.fetch_add(1, std::memory_order_relaxed);
    log("control loop %s", stalled ? "STALLED: DDS heartbeat withheld" : "progressing again: DDS heartbeat resumed");
  }
  loop_stall_reported_ = stalled;
  return !stalled;
}

app::LinkEvents EndcapNode::link_events() const noexcept {
  return {host_losses_.load(std::memory_order_relaxed), host_returns_.load(std::memory_order_relaxed),
          link_cuts_.load(std::memory_order_relaxed), loop_stalls_.load(std::memory_order_relaxed),
          rejoins_.load(std::memory_order_relaxed)};
}

void EndcapNode::send_telemetry() {
  if (!loop_seen_) return;
  const app::Telemetry& t = last_telemetry_.telemetry;
  m::Telemetry_ msg;
  msg.format_version(msgs::kFormatVersion);
  msg.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  msg.seq(++telemetry_sequence_);
  ActivePolicy active;
  ClockSample sample;
  bool synced = false;
  {
    std::lock_guard lock(mutex_);
    active = active_;
    sample = sync_.estimator().best();
    synced = sync_.estimator().synced();
  }
  msg.host_time_ns(synced ? last_telemetry_.local_ns + sample.offset_ns : 0);
  msg.loop_time_ns(t.time_ns);
  msg.cycle(t.cycle);
  msg.mode(static_cast<std::uint8_t>(t.mode));
  msg.fault(static_cast<std::uint8_t>(t.fault));
  msg.motor_count(t.motor_count);
  msg.subinterval(t.subinterval);
  msg.cutoff_mask(t.cutoff_mask);
  msg.drives_enabled(t.drives_enabled);
  std::array<double, 4> commanded{}, measured{}, tension{};
  for (std::size_t i = 0; i < 4 && i < core::kMaxMotorsPerEndcap; ++i) {
    commanded[i] = t.commanded_rest_length_m[i];
    measured[i] = t.measured_rest_length_m[i];
    tension[i] = t.tension_n[i];
  }
  msg.commanded_rest_length_m(commanded);
  msg.measured_rest_length_m(measured);
  msg.tension_n(tension);
  msg.loop_overruns(t.overruns);
  msg.active_policy_id(active.policy_id);
  msg.active_policy_version(active.policy_version);
  dds_->telemetry->write(&msg);
}

void EndcapNode::send_heartbeat(std::int64_t now) {
  if (!loop_alive(now)) return;
  m::Heartbeat_ hb;
  hb.format_version(msgs::kFormatVersion);
  hb.source(static_cast<std::int16_t>(config_.endcap_id));
  hb.seq(++heartbeat_sequence_);
  hb.time_ns(now);
  hb.mode(static_cast<std::uint8_t>(last_telemetry_.telemetry.mode));
  hb.fault(static_cast<std::uint8_t>(last_telemetry_.telemetry.fault));
  {
    std::lock_guard lock(mutex_);
    hb.active_policy_id(active_.policy_id);
    hb.active_policy_version(active_.policy_version);
    hb.clock_synced(sync_.estimator().synced());
    hb.clock_offset_ns(sync_.estimator().best().offset_ns);
    hb.clock_round_trip_ns(sync_.estimator().best().round_trip_ns);
  }
  hb.host_lost(host_lost_.load());
  hb.host_loss_action(static_cast<std::uint8_t>(config_.host_loss));
  hb.loop_overruns(last_telemetry_.telemetry.overruns);
  hb.life_id(life_id_);
  hb.estops_received(estops_.load(std::memory_order_acquire));
  dds_->heartbeat->write(&hb);
}

}  // namespace tensegrity::fw::comms

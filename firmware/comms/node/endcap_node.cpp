// SPDX-License-Identifier: Apache-2.0
// EndcapNode: construction, the node thread and the loop's side of the hand-over.
// The decisions are the parts' (endcap_node.hpp); the participant and its
// listeners are in node_listeners.cpp.
#include "firmware/comms/node/endcap_node.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <random>

#include "firmware/comms/node/node_dds.hpp"
#include "firmware/comms/node/node_messages.hpp"
#include "core/table.hpp"
#include "tensegrity_msgs/msg/TimeSync.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

namespace {

std::int64_t period_ns(double rate_hz) { return static_cast<std::int64_t>(std::llround(1e9 / rate_hz)); }

// Validated before any part is built from it.
EndcapNodeConfig checked(EndcapNodeConfig config) {
  config.expect.endcap_id = config.endcap_id;
  validate(config);
  return config;
}

std::uint64_t random_seed() {
  std::random_device random;
  return random() ^ (static_cast<std::uint64_t>(random()) << 32);
}

}  // namespace

EndcapNode::EndcapNode(const EndcapNodeConfig& config, Clock& clock, app::PolicyStore* store)
    : config_(checked(config)),
      clock_(clock),
      log_(config_.endcap_id, config_.log),
      sync_(random_seed(), log_),
      commands_(config_.endcap_id, msgs::kFormatVersion, core::seconds_to_ns(config_.command_max_age_s),
                config_.start_grid_ns, std::random_device{}() | 1U, log_),
      tables_(
          config_.expect, core::seconds_to_ns(config_.loop_ack_timeout_s), store,
          [this](const PolicyTableMsg& msg, PolicyReason reason, const std::string& text) {
            // On both participants during a rejoin's overlap: which one the host
            // hears is not known, and an uploader takes the first ack of a
            // sequence and ignores the rest.
            m::PolicyAck_ ack = policy_ack_message(facts(), msg, reason, text);
            participants_->current()->policy_ack->write(&ack);
            if (NodeParticipant* old = participants_->retiring()) old->policy_ack->write(&ack);
          },
          log_),
      host_(config_.host_timeout_s, config_.host_boot_grace_s, config_.host_loss, msgs::kFormatVersion, log_),
      rejoin_(config_.endcap_id, config_.unheard_rejoin_s, log_),
      loop_watch_(config_.loop_progress, config_.loop_stall_timeout_s, log_),
      faults_(config_.link_cut, config_.mute_requests, log_),
      schedule_(period_ns(config_.telemetry_rate_hz), period_ns(config_.heartbeat_rate_hz),
                core::seconds_to_ns(config_.time_sync_interval_s)),
      participants_(std::make_unique<Participants>()) {}

EndcapNode::~EndcapNode() { stop(); }

void EndcapNode::start() {
  if (running_.load()) return;
  participants_->adopt(make_participant());
  const std::int64_t now = clock_.now_ns();
  schedule_.start(now);
  loop_watch_.start(now);
  host_.start(now);
  rejoin_.start(now);
  running_.store(true);
  thread_ = std::thread([this] { run(); });
}

void EndcapNode::stop() noexcept {
  if (running_.exchange(false)) {
    wake();
    if (thread_.joinable()) thread_.join();
  }
  participants_->close();
}

void EndcapNode::publish(const app::Telemetry& telemetry) noexcept {
  // Stamped with the node's clock so the node can map loop time <-> its own time.
  const std::int64_t now = clock_.now_ns();
  // The command handler's copy first: the node acks an upload from telemetry_in_,
  // and a start sent on that ack must find the table there.
  commands_.note_loop(LoopPoint{LoopClockPoint{telemetry.time_ns, now},
                                LoopReadiness{telemetry.drives_enabled, telemetry.fault, telemetry.has_table}});
  telemetry_in_.write(StampedTelemetry{telemetry, now});
}

app::LinkEvents EndcapNode::link_events() const noexcept {
  return {host_.losses(), host_.returns(), faults_.cuts(), loop_watch_.stalls(), rejoin_.rejoins()};
}

NodeFacts EndcapNode::facts() const {
  return {config_.endcap_id, tables_.active(),    sync_.view(),      host_.lost(),
          config_.host_loss, commands_.life_id(), commands_.estops()};
}

void EndcapNode::wake() {
  {
    std::lock_guard lock(wake_mutex_);
    woken_ = true;
  }
  wake_cv_.notify_one();
}

void EndcapNode::run() {
  while (running_.load()) {
    const std::int64_t now = clock_.now_ns();
    service(now);
    std::int64_t next = schedule_.next_ns();
    if (rejoin_.pending()) next = std::min(next, rejoin_.next_attempt_ns());
    // The loop takes a table within a cycle or two: look again soon, the ack waits on it.
    if (tables_.awaiting_loop()) next = std::min(next, now + 1'000'000);
    const std::int64_t wait_ns = std::max<std::int64_t>(0, next - clock_.now_ns());
    std::unique_lock lock(wake_mutex_);
    wake_cv_.wait_for(lock, std::chrono::nanoseconds(wait_ns), [this] { return woken_ || !running_.load(); });
    woken_ = false;
  }
}

void EndcapNode::service(std::int64_t now) {
  if (faults_.poll()) participants_->current()->muted.store(true, std::memory_order_relaxed);
  StampedTelemetry t;
  if (telemetry_in_.read(t)) {
    last_telemetry_ = t;
    loop_seen_ = true;
  }
  take_samples(*participants_->current(), now);
  // During a rejoin's overlap the old participant may be the only one that hears the
  // host: its heartbeats and tables count as much as the new one's.
  if (NodeParticipant* old = participants_->retiring()) take_samples(*old, now);
  tables_.poll(now, loop_seen_ ? &last_telemetry_.telemetry : nullptr);
  if (host_.poll(now) && rejoin_.host_lost(host_.last_heard_ns(), loop_watch_.stalled())) rejoin();
  const RejoinWatch::Step step =
      rejoin_.poll(now, {host_.seen(), host_.lost(), loop_watch_.stalled()}, participants_->retiring() != nullptr);
  if (step.retire_old) participants_->retire();
  if (step.rejoin) rejoin();
  send_reports(now);
}

void EndcapNode::take_samples(NodeParticipant& p, std::int64_t now) {
  m::Heartbeat_ hb;
  dds::SampleInfo info;
  while (p.host_heartbeat->take_next_sample(&hb, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || !host_.accepts(hb.format_version())) continue;
    rejoin_.heard(hb.heard_endcaps(), now, host_.fresh(), &p == participants_->current());
    host_.heard(now);
  }
  PolicyTableMsg msg;
  while (p.policy->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
    if (info.valid_data) tables_.offer(msg);
  }
}

void EndcapNode::send_reports(std::int64_t now) {
  NodeParticipant& p = *participants_->current();
  if (schedule_.telemetry_due(now) && loop_seen_) {
    m::Telemetry_ msg =
        telemetry_message(facts(), ++telemetry_sequence_, last_telemetry_.telemetry, last_telemetry_.local_ns);
    p.telemetry->write(&msg);
  }
  if (schedule_.heartbeat_due(now) && loop_watch_.alive(now)) {
    m::Heartbeat_ hb = heartbeat_message(facts(), ++heartbeat_sequence_, now, last_telemetry_.telemetry);
    p.heartbeat->write(&hb);
  }
  sync_.settle(clock_.now_ns());
  if (schedule_.sync_due(now)) {
    m::TimeSyncRequest_ req;
    req.format_version(msgs::kFormatVersion);
    req.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
    req.seq(schedule_.sync_requests());
    const SharedTimeSync::Request r = sync_.request(clock_);
    req.t1_ns(r.t1_ns);
    req.nonce(r.nonce);
    p.sync_request->write(&req);
  }
  if (schedule_.unsynced_report_due(now)) sync_.report_if_unsynced(schedule_.sync_requests());
}

// On the node thread, the only one that makes or closes participants. The new one
// is made before the old one goes (node_dds.hpp: Participants).
void EndcapNode::rejoin() {
  std::unique_ptr<NodeParticipant> fresh;
  try {
    fresh = make_participant();
  } catch (const std::exception& e) {
    rejoin_.failed(clock_.now_ns(), e.what());
    return;
  }
  participants_->adopt(std::move(fresh));
  // Counted from when it exists: a secured participant takes a second or more to make.
  const std::int64_t made = clock_.now_ns();
  rejoin_.made(made);
  // Send at once on the new participant; a table half way to the loop is acked from it.
  schedule_.restart(made);
}

}  // namespace tensegrity::fw::comms

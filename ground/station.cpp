// SPDX-License-Identifier: Apache-2.0
#include "ground/station.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>

#include "firmware/hal/monotonic.hpp"
#include "ground/station_dds.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::ground {

std::int64_t Station::now_ns() { return fw::monotonic_ns(); }

Station::Station(const StationOptions& options) : options_(options), dds_(std::make_unique<Dds>()) {
  Dds& d = *dds_;
  d.participant = msgs::create_participant(options.domain, options.name, {}, options.enclave_dir, &d.writers);
  d.publisher = d.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  // Every end cap's reports, each from its own partition (msgs/endcap_writers.hpp).
  d.subscriber = d.participant->create_subscriber(msgs::endcap_reports_qos());
  if (d.publisher == nullptr || d.subscriber == nullptr) throw msgs::DdsError("cannot create publisher/subscriber");
  d.policy = d.writer(msgs::kPolicyTableTopic, dds::TypeSupport(new msg::PolicyTable_PubSubType()), &d.policy_readers);
  d.command = d.writer(msgs::kCommandTopic, dds::TypeSupport(new msg::Command_PubSubType()), &d.command_readers);
  d.heartbeat = d.writer(msgs::kHostHeartbeatTopic, dds::TypeSupport(new msg::Heartbeat_PubSubType()));
  d.sync_reply = d.writer(msgs::kTimeSyncReplyTopic, dds::TypeSupport(new msg::TimeSyncReply_PubSubType()));
  d.reader(*this, msgs::kPolicyAckTopic, dds::TypeSupport(new msg::PolicyAck_PubSubType()),
           &StationListeners::policy_acks);
  d.reader(*this, msgs::kCommandAckTopic, dds::TypeSupport(new msg::CommandAck_PubSubType()),
           &StationListeners::command_acks);
  d.reader(*this, msgs::kTelemetryTopic, dds::TypeSupport(new msg::Telemetry_PubSubType()),
           &StationListeners::telemetry);
  d.reader(*this, msgs::kEndcapHeartbeatTopic, dds::TypeSupport(new msg::Heartbeat_PubSubType()),
           &StationListeners::heartbeats);
  if (options.serve_time) {
    d.reader(*this, msgs::kTimeSyncRequestTopic, dds::TypeSupport(new msg::TimeSyncRequest_PubSubType()),
             &StationListeners::time_sync);
  }
  if (options.publish_heartbeat) heartbeat_thread_ = std::make_unique<std::thread>([this] { heartbeat_loop(); });
}

Station::~Station() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_cv_.notify_all();
  if (heartbeat_thread_) heartbeat_thread_->join();
  // Entities deleted while dds_ still points at them (reset() would null it first,
  // under the feet of the receive thread's callbacks).
  dds_->close();
  dds_.reset();
}

void Station::heartbeat_loop() {
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / options_.heartbeat_rate_hz));
  std::uint32_t seq = 0;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    msg::Heartbeat_ hb;
    hb.format_version(msgs::kFormatVersion);
    hb.source(-1);
    hb.seq(++seq);
    const std::int64_t now = now_ns();
    hb.time_ns(now);
    hb.heard_endcaps(heard(now, kHeardFreshS));
    dds_->heartbeat->write(&hb);
    lock.lock();
    stop_cv_.wait_for(lock, period, [this] { return stopping_; });
  }
}

void Station::write_policy(const msg::PolicyTable_& table) {
  msg::PolicyTable_ copy = table;
  dds_->policy->write(&copy);
}

void Station::write_command(const msg::Command_& command) {
  msg::Command_ copy = command;
  dds_->command->write(&copy);
}

std::vector<msg::PolicyAck_> Station::take_policy_acks() {
  std::lock_guard lock(mutex_);
  return std::exchange(policy_acks_, {});
}

std::vector<msg::CommandAck_> Station::take_command_acks() {
  std::lock_guard lock(mutex_);
  return std::exchange(command_acks_, {});
}

void Station::wait_for_policy_acks(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  const std::int64_t wait = deadline_ns - now_ns();
  if (wait <= 0) return;
  changed_.wait_for(lock, std::chrono::nanoseconds(wait), [this] { return !policy_acks_.empty(); });
}

void Station::wait_for_command_acks(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  const std::int64_t wait = deadline_ns - now_ns();
  if (wait <= 0) return;
  changed_.wait_for(lock, std::chrono::nanoseconds(wait), [this] { return !command_acks_.empty(); });
}

std::array<EndcapStatus, kEndcapCount> Station::snapshot() const {
  const std::uint16_t reach = reached();  // its own locks: taken before this station's
  std::unique_lock lock(mutex_);
  std::array<EndcapStatus, kEndcapCount> out = status_;
  lock.unlock();
  for (int e = 0; e < kEndcapCount; ++e) out[static_cast<std::size_t>(e)].reached = (reach & (1U << e)) != 0;
  return out;
}

std::uint16_t Station::heard(std::int64_t now_ns, double fresh_s) const {
  const auto fresh_ns = static_cast<std::int64_t>(fresh_s * 1e9);
  std::lock_guard lock(mutex_);
  std::uint16_t mask = 0;
  for (int e = 0; e < kEndcapCount; ++e) {
    const EndcapStatus& s = status_[static_cast<std::size_t>(e)];
    if (s.seen && now_ns - s.heartbeat_host_ns <= fresh_ns) mask = static_cast<std::uint16_t>(mask | (1U << e));
  }
  return mask;
}

std::uint16_t Station::reached() const {
  const Dds& d = *dds_;
  return static_cast<std::uint16_t>(d.writers.endcaps_of_participants(
      [&d](const auto& p) { return d.policy_readers.reaches(p) && d.command_readers.reaches(p); }));
}

bool Station::wait_for_endcaps(std::uint16_t mask, bool synced, std::int64_t deadline_ns) const {
  for (;;) {
    const std::uint16_t reach = reached();  // its own locks: taken before this station's
    std::unique_lock lock(mutex_);
    bool ready = (reach & mask) == mask;
    for (int i = 0; i < kEndcapCount && ready; ++i) {
      if ((mask & (1U << i)) == 0) continue;
      ready = status_[i].seen && (!synced || status_[i].heartbeat.clock_synced()) &&
              (!options_.publish_heartbeat || !status_[i].heartbeat.host_lost());
    }
    if (ready) return true;
    const std::int64_t wait = deadline_ns - now_ns();
    if (wait <= 0) return false;
    // Matching is not signalled here: looked at again every 20 ms.
    changed_.wait_for(lock, std::chrono::nanoseconds(std::min<std::int64_t>(wait, 20'000'000)));
  }
}

void Station::on_telemetry(std::function<void(const msg::Telemetry_&, std::int64_t)> callback) {
  std::lock_guard lock(mutex_);
  telemetry_callback_ = std::move(callback);
}

std::uint64_t Station::impostor_samples() const {
  std::lock_guard lock(mutex_);
  return impostor_samples_;
}

std::uint64_t Station::time_sync_replies() const {
  std::lock_guard lock(mutex_);
  return sync_replies_;
}

}  // namespace tensegrity::ground

// SPDX-License-Identifier: Apache-2.0
// EndcapNode: construction, the DDS entities, the node thread and the loop's side
// of the hand-over. The work itself is in node_tables.cpp, node_commands.cpp,
// node_status.cpp, node_time_sync.cpp and node_rejoin.cpp.
#include "firmware/comms/node/endcap_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <random>

#include "firmware/comms/node/node_dds.hpp"
#include "core/table.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

namespace {
constexpr int kInitialSyncBurst = 8;
constexpr std::int64_t kInitialSyncSpacingNs = 25'000'000;
// While unsynchronized the log says why, this often (a start is refused until then).
constexpr std::int64_t kUnsyncedReportNs = 5'000'000'000;
std::int64_t period_ns(double rate_hz) { return static_cast<std::int64_t>(std::llround(1e9 / rate_hz)); }
}  // namespace

EndcapNode::EndcapNode(const EndcapNodeConfig& config, Clock& clock, app::PolicyStore* store)
    : config_(config),
      clock_(clock),
      store_(store),
      gate_(config.endcap_id, msgs::kFormatVersion, core::seconds_to_ns(config.command_max_age_s)),
      start_mapper_(config.start_grid_ns),
      sync_(std::random_device{}() ^ (static_cast<std::uint64_t>(std::random_device{}()) << 32)) {
  config_.expect.endcap_id = config_.endcap_id;
  validate(config_);
  app::StoredTable stored;
  if (store_ != nullptr && store_->current(stored)) {
    active_ = stored.identity;
    active_table_ = stored.table;
    have_active_table_ = true;
  }
}

EndcapNode::~EndcapNode() { stop(); }

void EndcapNode::start() {
  if (running_.load()) return;
  dds_ = make_dds();
  const std::int64_t now = clock_.now_ns();
  next_telemetry_ns_ = now;
  next_heartbeat_ns_ = now;
  next_sync_ns_ = now;
  next_unsynced_report_ns_ = now + kUnsyncedReportNs;
  loop_progress_ns_ = now;
  participant_since_ns_ = now;
  started_ns_ = now;
  rejoin_wait_s_ = config_.unheard_rejoin_s;
  running_.store(true);
  thread_ = std::thread([this] { run(); });
}

std::unique_ptr<EndcapNode::Dds> EndcapNode::make_dds() {
  auto d = std::make_unique<Dds>();
  const msgs::LinkFaults faults{config_.link_cut, config_.mute_requests != nullptr ? &d->muted : nullptr};
  d->participant = msgs::create_participant(config_.domain, "endcap" + std::to_string(config_.endcap_id), faults,
                                            config_.enclave_dir);
  // Reports go out in this end cap's own partition, the only one its identity may
  // write in (msgs/endcap_writers.hpp); orders come in the default one.
  d->publisher = d->participant->create_publisher(msgs::endcap_publisher_qos(config_.endcap_id));
  d->subscriber = d->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (d->publisher == nullptr || d->subscriber == nullptr) throw msgs::DdsError("cannot create publisher/subscriber");
  d->policy_ack = d->writer(msgs::kPolicyAckTopic, dds::TypeSupport(new m::PolicyAck_PubSubType()));
  d->command_ack = d->writer(msgs::kCommandAckTopic, dds::TypeSupport(new m::CommandAck_PubSubType()));
  d->telemetry = d->writer(msgs::kTelemetryTopic, dds::TypeSupport(new m::Telemetry_PubSubType()));
  d->heartbeat = d->writer(msgs::kEndcapHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()));
  d->sync_request = d->writer(msgs::kTimeSyncRequestTopic, dds::TypeSupport(new m::TimeSyncRequest_PubSubType()));
  Dds* raw = d.get();  // the listeners reach their own entities, never through dds_
  auto listener = [this, raw](std::function<void()> fn, const char* topic) {
    raw->listeners.push_back(std::make_unique<CallbackListener>(std::move(fn), topic, config_.endcap_id, config_.log));
    return raw->listeners.back().get();
  };
  // Readers last: a callback may fire as soon as a reader exists, and it may use
  // the writers. The two that work in the receive thread reach their reader
  // through `raw` under its mutex.
  dds::DataReader* sync_reply =
      d->reader(msgs::kTimeSyncReplyTopic, dds::TypeSupport(new m::TimeSyncReply_PubSubType()),
                listener([this, raw] { on_time_sync_reply(*raw); }, msgs::kTimeSyncReplyTopic.name));
  const msgs::TopicSpec fresh_commands{msgs::kCommandTopic.name, msgs::kCommandTopic.type, msgs::kProfileFreshCommands,
                                       msgs::kCommandTopic.writer};
  dds::DataReader* command = d->reader(fresh_commands, dds::TypeSupport(new m::Command_PubSubType()),
                                       listener([this, raw] { on_commands(*raw); }, msgs::kCommandTopic.name));
  {
    std::lock_guard lock(d->callback_mutex);
    d->sync_reply = sync_reply;
    d->command = command;
  }
  // These two only wake the node thread, which reads them once this object is dds_.
  d->policy = d->reader(msgs::kPolicyTableTopic, dds::TypeSupport(new m::PolicyTable_PubSubType()),
                        listener([this] { wake(); }, msgs::kPolicyTableTopic.name));
  d->host_heartbeat = d->reader(msgs::kHostHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()),
                                listener([this] { wake(); }, msgs::kHostHeartbeatTopic.name));
  return d;
}

void EndcapNode::stop() noexcept {
  if (running_.exchange(false)) {
    wake();
    if (thread_.joinable()) thread_.join();
  }
  pair_participants(false);
  // Entities deleted while dds_ still points at them (reset() would null it first).
  if (dds_) dds_->close();
  dds_.reset();
  retire();
}

bool EndcapNode::try_take_table(app::HostTable& out) noexcept { return tables_.pop(out); }
bool EndcapNode::try_take_command(app::HostCommand& out) noexcept { return commands_.pop(out); }

void EndcapNode::publish(const app::Telemetry& telemetry) noexcept {
  // Stamped with the node's clock so the node can map loop time <-> its own time.
  const std::int64_t now = clock_.now_ns();
  // The listener's copy first: the node acks an upload from telemetry_in_, and a start
  // sent on that ack must find the table in loop_in_.
  loop_in_.write(LoopPoint{LoopClockPoint{telemetry.time_ns, now},
                           LoopReadiness{telemetry.drives_enabled, telemetry.fault, telemetry.has_table}});
  telemetry_in_.write(StampedTelemetry{telemetry, now});
}

ActivePolicy EndcapNode::active_policy() const {
  std::lock_guard lock(mutex_);
  return active_;
}
ClockSample EndcapNode::clock_sample() const {
  std::lock_guard lock(mutex_);
  return sync_.estimator().best();
}
bool EndcapNode::clock_synced() const {
  std::lock_guard lock(mutex_);
  return sync_.estimator().synced();
}
TimeSyncCounters EndcapNode::time_sync_counters() const {
  std::lock_guard lock(mutex_);
  return sync_.counters();
}

void EndcapNode::log(const char* format, ...) const {
  if (!config_.log) return;
  char text[400];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  std::fprintf(stderr, "endcap %d: %s\n", config_.endcap_id, text);
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
    std::int64_t next = std::min({next_telemetry_ns_, next_heartbeat_ns_, next_sync_ns_});
    if (remake_pending_) next = std::min(next, next_remake_ns_);
    // The loop takes a table within a cycle or two: look again soon, the ack waits on it.
    if (in_flight_.active && !in_flight_.answered) next = std::min(next, now + 1'000'000);
    const std::int64_t wait_ns = std::max<std::int64_t>(0, next - clock_.now_ns());
    std::unique_lock lock(wake_mutex_);
    wake_cv_.wait_for(lock, std::chrono::nanoseconds(wait_ns), [this] { return woken_ || !running_.load(); });
    woken_ = false;
  }
}

void EndcapNode::service(std::int64_t now) {
  report_link_cut();
  apply_mute_fault();
  StampedTelemetry t;
  if (telemetry_in_.read(t)) {
    last_telemetry_ = t;
    loop_seen_ = true;
  }
  handle_host_heartbeats(*dds_, now);
  if (retiring_ != nullptr) handle_host_heartbeats(*retiring_, now);  // still hears the host
  handle_tables(now);
  check_host_loss(now);
  check_heard(now);  // may make a new participant (node_rejoin.cpp)
  if (now >= next_telemetry_ns_) {
    send_telemetry();
    next_telemetry_ns_ += period_ns(config_.telemetry_rate_hz);
    if (next_telemetry_ns_ <= now) next_telemetry_ns_ = now + period_ns(config_.telemetry_rate_hz);  // fell behind
  }
  if (now >= next_heartbeat_ns_) {
    send_heartbeat(now);
    next_heartbeat_ns_ = std::max(next_heartbeat_ns_ + period_ns(config_.heartbeat_rate_hz), now);
  }
  {
    std::lock_guard lock(mutex_);
    sync_.settle(clock_.now_ns());
  }
  if (now >= next_sync_ns_) {
    send_time_sync_request();
    const bool burst = sync_sequence_ < kInitialSyncBurst;
    next_sync_ns_ = now + (burst ? kInitialSyncSpacingNs : core::seconds_to_ns(config_.time_sync_interval_s));
  }
  if (now >= next_unsynced_report_ns_) {
    next_unsynced_report_ns_ = now + kUnsyncedReportNs;
    report_if_unsynced();
  }
}

}  // namespace tensegrity::fw::comms

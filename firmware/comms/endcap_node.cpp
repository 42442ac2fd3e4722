// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/endcap_node.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <vector>

#include "msgs/dds.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::fw::comms {

namespace dds = eprosima::fastdds::dds;
namespace m = tensegrity_msgs::msg::dds_;

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr int kInitialSyncBurst = 8;
constexpr std::int64_t kInitialSyncSpacingNs = 25'000'000;
constexpr std::size_t kRecentCommands = 32;
const char* const kIdentityBlob = "policy-identity";

std::int64_t period_ns(double rate_hz) { return static_cast<std::int64_t>(std::llround(1e9 / rate_hz)); }
std::int64_t to_ns(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * 1e9)); }

// Calls `fn` from Fast DDS's receive thread when a reader has data.
class CallbackListener final : public dds::DataReaderListener {
 public:
  CallbackListener(std::function<void()> fn, std::string topic, int endcap, bool log)
      : fn_(std::move(fn)), topic_(std::move(topic)), endcap_(endcap), log_(log) {}
  void on_data_available(dds::DataReader*) override { fn_(); }
  void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus& status) override {
    // Loud: a peer with other QoS on one of our topics is a configuration error.
    if (log_) {
      std::fprintf(stderr, "endcap %d: incompatible QoS offered on %s (policy id %u)\n", endcap_, topic_.c_str(),
                   static_cast<unsigned>(status.last_policy_id));
    }
  }

 private:
  std::function<void()> fn_;
  std::string topic_;
  int endcap_;
  bool log_;
};

}  // namespace

const char* to_string(HostLossAction action) {
  return action == HostLossAction::stop ? "stop" : "continue";
}

HostLossAction parse_host_loss_action(const std::string& text) {
  if (text == "continue") return HostLossAction::continue_gait;
  if (text == "stop") return HostLossAction::stop;
  throw std::invalid_argument("host-loss action '" + text + "': expected 'continue' or 'stop'");
}

void validate(const EndcapNodeConfig& c) {
  auto positive = [](double v, const char* name, double max) {
    if (!std::isfinite(v) || v <= 0.0 || v > max) {
      throw std::invalid_argument(std::string(name) + " = " + std::to_string(v) + ": expected > 0 and <= " +
                                  std::to_string(max));
    }
  };
  if (c.endcap_id < 0 || c.endcap_id > 15) {
    throw std::invalid_argument("endcap_id = " + std::to_string(c.endcap_id) + ": expected 0..15");
  }
  if (c.domain < 0 || c.domain > 232) {
    throw std::invalid_argument("domain = " + std::to_string(c.domain) + ": expected 0..232");
  }
  positive(c.telemetry_rate_hz, "telemetry_rate_hz", 1000.0);
  positive(c.heartbeat_rate_hz, "heartbeat_rate_hz", 100.0);
  positive(c.time_sync_interval_s, "time_sync_interval_s", 60.0);
  positive(c.host_timeout_s, "host_timeout_s", 3600.0);
  positive(c.loop_ack_timeout_s, "loop_ack_timeout_s", 60.0);
  positive(c.command_max_age_s, "command_max_age_s", 3600.0);
  positive(c.loop_stall_timeout_s, "loop_stall_timeout_s", 60.0);
  if (c.start_grid_ns < 0) throw std::invalid_argument("start_grid_ns = " + std::to_string(c.start_grid_ns) + ": expected >= 0");
}

struct EndcapNode::Dds {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataWriter* policy_ack = nullptr;
  dds::DataWriter* command_ack = nullptr;
  dds::DataWriter* telemetry = nullptr;
  dds::DataWriter* heartbeat = nullptr;
  dds::DataWriter* sync_request = nullptr;
  dds::DataReader* policy = nullptr;
  dds::DataReader* command = nullptr;
  dds::DataReader* host_heartbeat = nullptr;
  dds::DataReader* sync_reply = nullptr;
  std::vector<std::unique_ptr<CallbackListener>> listeners;
  // The time-sync listener runs on Fast DDS's receive thread and uses this object,
  // from the moment its reader exists until the participant is gone: close() lets
  // a callback in progress finish (it holds the mutex), then refuses later ones,
  // and only then deletes anything. Without it, a reply arriving while the node
  // stopped reached through a half-destroyed object (seen: SIGSEGV at exit).
  std::mutex callback_mutex;
  bool closed = false;  // guarded by callback_mutex

  ~Dds() { close(); }
  void close() noexcept {
    {
      std::lock_guard lock(callback_mutex);
      closed = true;
    }
    msgs::delete_participant(participant);
    participant = nullptr;
  }

  dds::DataWriter* writer(const msgs::TopicSpec& spec, dds::TypeSupport type) {
    return msgs::create_writer(*participant, *publisher, spec, type);
  }
  dds::DataReader* reader(const msgs::TopicSpec& spec, dds::TypeSupport type, CallbackListener* listener) {
    return msgs::create_reader(*participant, *subscriber, spec, type, listener);
  }
};

EndcapNode::EndcapNode(const EndcapNodeConfig& config, Clock& clock, Storage* storage)
    : config_(config), clock_(clock), storage_(storage) {
  config_.expect.endcap_id = config_.endcap_id;
  validate(config_);
  load_persisted_identity();
}

EndcapNode::~EndcapNode() { stop(); }

void EndcapNode::start() {
  if (running_.load()) return;
  auto d = std::make_unique<Dds>();
  d->participant = msgs::create_participant(config_.domain, "endcap" + std::to_string(config_.endcap_id), config_.link_cut);
  d->publisher = d->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  d->subscriber = d->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (d->publisher == nullptr || d->subscriber == nullptr) throw msgs::DdsError("cannot create publisher/subscriber");
  d->policy_ack = d->writer(msgs::kPolicyAckTopic, dds::TypeSupport(new m::PolicyAck_PubSubType()));
  d->command_ack = d->writer(msgs::kCommandAckTopic, dds::TypeSupport(new m::CommandAck_PubSubType()));
  d->telemetry = d->writer(msgs::kTelemetryTopic, dds::TypeSupport(new m::Telemetry_PubSubType()));
  d->heartbeat = d->writer(msgs::kEndcapHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()));
  d->sync_request = d->writer(msgs::kTimeSyncRequestTopic, dds::TypeSupport(new m::TimeSyncRequest_PubSubType()));
  Dds* raw = d.get();  // `d` is moved into dds_ below; the listeners outlive that
  auto listener = [this, raw](std::function<void()> fn, const char* topic) {
    raw->listeners.push_back(std::make_unique<CallbackListener>(std::move(fn), topic, config_.endcap_id, config_.log));
    return raw->listeners.back().get();
  };
  // Readers last: a callback may fire as soon as a reader exists (replies to other
  // end caps are on the same topic), and it may use the writers. It reaches the
  // reader through `raw` under its mutex, never through dds_ (not yet set here).
  dds::DataReader* sync_reply =
      d->reader(msgs::kTimeSyncReplyTopic, dds::TypeSupport(new m::TimeSyncReply_PubSubType()),
                listener([this, raw] { on_time_sync_reply(*raw); }, msgs::kTimeSyncReplyTopic.name));
  {
    std::lock_guard lock(d->callback_mutex);
    d->sync_reply = sync_reply;
  }
  dds_ = std::move(d);
  const std::int64_t now = clock_.now_ns();
  started_ns_ = now;
  next_telemetry_ns_ = now;
  next_heartbeat_ns_ = now;
  next_sync_ns_ = now;
  loop_progress_ns_ = now;
  running_.store(true);
  // The remaining readers wake the node thread; created after dds_ is set.
  dds_->policy = dds_->reader(msgs::kPolicyTableTopic, dds::TypeSupport(new m::PolicyTable_PubSubType()),
                              listener([this] { wake(); }, msgs::kPolicyTableTopic.name));
  dds_->command = dds_->reader(msgs::kCommandTopic, dds::TypeSupport(new m::Command_PubSubType()),
                               listener([this] { wake(); }, msgs::kCommandTopic.name));
  dds_->host_heartbeat = dds_->reader(msgs::kHostHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()),
                                      listener([this] { wake(); }, msgs::kHostHeartbeatTopic.name));
  thread_ = std::thread([this] { run(); });
}

void EndcapNode::stop() noexcept {
  if (running_.exchange(false)) {
    wake();
    if (thread_.joinable()) thread_.join();
  }
  // Entities deleted while dds_ still points at them (reset() would null it first).
  if (dds_) dds_->close();
  dds_.reset();
}

bool EndcapNode::try_take_table(app::HostTable& out) noexcept { return tables_.pop(out); }
bool EndcapNode::try_take_command(app::HostCommand& out) noexcept { return commands_.pop(out); }

void EndcapNode::publish(const app::Telemetry& telemetry) noexcept {
  // Stamped with the node's clock so the node can map loop time <-> its own time.
  telemetry_in_.write(StampedTelemetry{telemetry, clock_.now_ns()});
}

ActivePolicy EndcapNode::active_policy() const {
  std::lock_guard lock(mutex_);
  return active_;
}
ClockSample EndcapNode::clock_sample() const {
  std::lock_guard lock(mutex_);
  return sync_.best();
}
bool EndcapNode::clock_synced() const {
  std::lock_guard lock(mutex_);
  return sync_.synced();
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
    // The loop takes a table within a cycle or two: look again soon, the ack waits on it.
    if (table_pending_) next = std::min(next, now + 1'000'000);
    const std::int64_t wait_ns = std::max<std::int64_t>(0, next - clock_.now_ns());
    std::unique_lock lock(wake_mutex_);
    wake_cv_.wait_for(lock, std::chrono::nanoseconds(wait_ns), [this] { return woken_ || !running_.load(); });
    woken_ = false;
  }
}

void EndcapNode::service(std::int64_t now) {
  report_link_cut();
  StampedTelemetry t;
  if (telemetry_in_.read(t)) {
    last_telemetry_ = t;
    loop_seen_ = true;
  }
  handle_host_heartbeats(now);
  handle_commands(now);
  handle_tables(now);
  check_host_loss(now);
  if (now >= next_telemetry_ns_) {
    send_telemetry(now);
    next_telemetry_ns_ += period_ns(config_.telemetry_rate_hz);
    if (next_telemetry_ns_ <= now) next_telemetry_ns_ = now + period_ns(config_.telemetry_rate_hz);  // fell behind
  }
  if (now >= next_heartbeat_ns_) {
    send_heartbeat(now);
    next_heartbeat_ns_ = std::max(next_heartbeat_ns_ + period_ns(config_.heartbeat_rate_hz), now);
  }
  if (now >= next_sync_ns_) {
    send_time_sync_request(now);
    const bool burst = sync_sequence_ < kInitialSyncBurst;
    next_sync_ns_ = now + (burst ? kInitialSyncSpacingNs : to_ns(config_.time_sync_interval_s));
  }
}

void EndcapNode::handle_tables(std::int64_t now) {
  m::PolicyTable_ msg;
  dds::SampleInfo info;
  while (dds_->policy->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || msg.target_endcap() != config_.endcap_id) continue;  // another end cap's table
    inbox_.push_back(msg);
  }
  if (table_pending_) finish_pending_table(now);
  while (!table_pending_ && !inbox_.empty()) {
    const m::PolicyTable_ incoming = inbox_.front();
    inbox_.pop_front();
    // A retry of the table just answered (its ack was lost or is late): same answer.
    if (have_last_ack_ && incoming.upload_sequence() == last_ack_upload_sequence_) {
      send_policy_ack(incoming, last_ack_reason_, last_ack_text_);
      continue;
    }
    PolicyCheck check = check_policy(incoming, config_.expect);
    if (check.reason == PolicyReason::wrong_format_version && config_.log) {
      std::fprintf(stderr, "endcap %d: REFUSED policy table: %s\n", config_.endcap_id, check.text.c_str());
    }
    if (check.reason != PolicyReason::accepted) {
      send_policy_ack(incoming, check.reason, check.text);
      continue;
    }
    const ActivePolicy active = active_policy();
    if (!active.policy_id.empty() && incoming.policy_id().to_string() == active.policy_id &&
        incoming.policy_version() == active.policy_version && incoming.checksum() == active.checksum) {
      send_policy_ack(incoming, PolicyReason::already_active, describe(PolicyReason::already_active));
      continue;
    }
    if (!incoming.force() && !active.policy_id.empty() && incoming.policy_version() <= active.policy_version) {
      char text[160];
      std::snprintf(text, sizeof text, "version %u is not newer than active %s v%u (use force)",
                    incoming.policy_version(), active.policy_id.c_str(), active.policy_version);
      send_policy_ack(incoming, PolicyReason::stale_version, text);
      continue;
    }
    app::HostTable handover;
    handover.sequence = ++loop_sequence_;
    handover.table = check.table;
    if (!tables_.push(handover)) {
      send_policy_ack(incoming, PolicyReason::loop_busy, "table mailbox to the control loop is full");
      continue;
    }
    table_pending_ = true;
    pending_msg_ = incoming;
    pending_loop_sequence_ = handover.sequence;
    pending_since_ns_ = now;
    finish_pending_table(now);
  }
}

void EndcapNode::finish_pending_table(std::int64_t now) {
  const app::Telemetry& t = last_telemetry_.telemetry;
  if (loop_seen_ && t.table_ack_sequence == pending_loop_sequence_) {
    table_pending_ = false;
    if (t.table_ack_error != core::TableError::none) {
      send_policy_ack(pending_msg_, from_table_error(t.table_ack_error),
                      std::string("control loop refused it: ") + core::describe(t.table_ack_error));
      return;
    }
    {
      std::lock_guard lock(mutex_);
      active_.policy_id = pending_msg_.policy_id().to_string();
      active_.policy_version = pending_msg_.policy_version();
      active_.checksum = pending_msg_.checksum();
    }
    persist_identity();
    if (config_.log) {
      std::fprintf(stderr, "endcap %d: policy %s v%u accepted\n", config_.endcap_id, pending_msg_.policy_id().c_str(),
                   pending_msg_.policy_version());
    }
    send_policy_ack(pending_msg_, PolicyReason::accepted, describe(PolicyReason::accepted));
  } else if (now - pending_since_ns_ > to_ns(config_.loop_ack_timeout_s)) {
    // The loop may still take it later; the ack says what we know now, and the
    // telemetry's active policy tells the rest.
    table_pending_ = false;
    send_policy_ack(pending_msg_, PolicyReason::loop_busy, describe(PolicyReason::loop_busy));
  }
}

void EndcapNode::send_policy_ack(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text) {
  m::PolicyAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  ack.upload_sequence(msg.upload_sequence());
  ack.accepted(is_accepted(reason));
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(text.substr(0, 128));
  const ActivePolicy active = active_policy();
  ack.active_policy_id(active.policy_id);
  ack.active_policy_version(active.policy_version);
  ack.active_checksum(active.checksum);
  dds_->policy_ack->write(&ack);
  have_last_ack_ = true;
  last_ack_upload_sequence_ = msg.upload_sequence();
  last_ack_reason_ = reason;
  last_ack_text_ = text;
  if (!is_accepted(reason) && config_.log) {
    std::fprintf(stderr, "endcap %d: policy %s v%u rejected: %s\n", config_.endcap_id, msg.policy_id().c_str(),
                 msg.policy_version(), text.c_str());
  }
}

void EndcapNode::handle_commands(std::int64_t now) {
  m::Command_ cmd;
  dds::SampleInfo info;
  while (dds_->command->take_next_sample(&cmd, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if ((cmd.endcap_mask() & (1U << config_.endcap_id)) == 0) continue;
    const auto issued = static_cast<std::uint64_t>(cmd.issued_host_time_ns());
    const auto seen = std::find_if(recent_commands_.begin(), recent_commands_.end(),
                                   [&](const RecentCommand& r) { return r.issued == issued && r.seq == cmd.seq(); });
    if (seen != recent_commands_.end()) {
      send_command_ack(cmd.seq(), seen->reason);
      continue;
    }
    CommandReason reason = CommandReason::accepted;
    app::HostCommand out;
    bool synced = false;
    ClockSample sample;
    {
      std::lock_guard lock(mutex_);
      synced = sync_.synced();
      sample = sync_.best();
    }
    if (cmd.format_version() != msgs::kFormatVersion) {
      reason = CommandReason::wrong_format_version;
      if (config_.log) {
        std::fprintf(stderr, "endcap %d: REFUSED command: format version %u, this end cap speaks %u\n",
                     config_.endcap_id, unsigned{cmd.format_version()}, unsigned{msgs::kFormatVersion});
      }
    } else if (synced && now + sample.offset_ns - cmd.issued_host_time_ns() > to_ns(config_.command_max_age_s)) {
      if (config_.log) {
        std::fprintf(stderr, "endcap %d: ignored command %u issued %.1f s ago (history replay)\n", config_.endcap_id,
                     cmd.seq(),
                     static_cast<double>(now + sample.offset_ns - cmd.issued_host_time_ns()) / 1e9);
      }
      continue;
    } else if (synced && cmd.issued_host_time_ns() < started_ns_ + sample.offset_ns) {
      // Issued before this program started: an order to its previous life, kept in
      // the writer's history (transient local). A restarted end cap acting on it
      // would restart a table it already plays (start on boot) at another phase.
      if (config_.log) {
        std::fprintf(stderr, "endcap %d: ignored command %u issued before this end cap started (history)\n",
                     config_.endcap_id, cmd.seq());
      }
      continue;
    } else if (cmd.kind() > 3) {
      reason = CommandReason::unknown_kind;
    } else {
      out.kind = static_cast<app::CommandKind>(cmd.kind());
      if (out.kind == app::CommandKind::start) {
        if (!synced) {
          reason = CommandReason::clock_not_synced;
        } else if (!loop_seen_) {
          reason = CommandReason::loop_not_running;
        } else {
          // host -> node clock -> loop clock (loop time advanced with the node's
          // clock since the loop's last publish).
          const std::int64_t local = cmd.start_host_time_ns() - sample.offset_ns;
          const std::int64_t since_last_cycle = local - last_telemetry_.local_ns;
          out.start_time_ns = last_telemetry_.telemetry.time_ns + since_last_cycle;
          if (config_.start_grid_ns > 0) {
            // Lockstep: whole grid steps after the last cycle (see the config).
            const std::int64_t g = config_.start_grid_ns;
            const std::int64_t steps = since_last_cycle >= 0 ? (since_last_cycle + g / 2) / g
                                                             : -((-since_last_cycle + g / 2) / g);
            out.start_time_ns = last_telemetry_.telemetry.time_ns + steps * g;
          }
        }
      }
      if (reason == CommandReason::accepted && !commands_.push(out)) reason = CommandReason::mailbox_full;
    }
    recent_commands_.push_back(RecentCommand{issued, cmd.seq(), reason});
    if (recent_commands_.size() > kRecentCommands) recent_commands_.pop_front();
    send_command_ack(cmd.seq(), reason);
    if (config_.log) {
      std::fprintf(stderr, "endcap %d: command %u kind %u: %s\n", config_.endcap_id, cmd.seq(),
                   unsigned{cmd.kind()}, describe(reason));
    }
  }
}

void EndcapNode::send_command_ack(std::uint32_t seq, CommandReason reason) {
  m::CommandAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  ack.seq(seq);
  ack.accepted(reason == CommandReason::accepted);
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(describe(reason));
  dds_->command_ack->write(&ack);
}

void EndcapNode::handle_host_heartbeats(std::int64_t now) {
  m::Heartbeat_ hb;
  dds::SampleInfo info;
  while (dds_->host_heartbeat->take_next_sample(&hb, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (hb.format_version() != msgs::kFormatVersion) {
      if (refused_format_++ % 100 == 0 && config_.log) {
        std::fprintf(stderr, "endcap %d: REFUSED host heartbeat: format version %u, this end cap speaks %u\n",
                     config_.endcap_id, unsigned{hb.format_version()}, unsigned{msgs::kFormatVersion});
      }
      continue;
    }
    last_host_heartbeat_ns_ = now;
    host_seen_ = true;
  }
}

// The flag is flipped from outside (a signal handler): said here, on the node's
// thread, so the log shows when the link went and came back.
void EndcapNode::report_link_cut() {
  if (config_.link_cut == nullptr) return;
  const bool cut = config_.link_cut->load(std::memory_order_relaxed);
  if (cut == link_was_cut_) return;
  link_was_cut_ = cut;
  if (config_.log) {
    std::fprintf(stderr, "endcap %d: DDS link %s (fault injection)\n", config_.endcap_id, cut ? "CUT" : "restored");
  }
}

void EndcapNode::check_host_loss(std::int64_t now) {
  const bool lost = host_seen_ && now - last_host_heartbeat_ns_ > to_ns(config_.host_timeout_s);
  if (lost == host_lost_.load()) return;
  host_lost_.store(lost);
  if (config_.log) {
    std::fprintf(stderr, "endcap %d: host %s (configured action: %s)\n", config_.endcap_id,
                 lost ? "LOST: no heartbeat" : "back", to_string(config_.host_loss));
  }
  if (lost && config_.host_loss == HostLossAction::stop) {
    app::HostCommand stop_command;
    stop_command.kind = app::CommandKind::stop;
    commands_.push(stop_command);
  }
}

void EndcapNode::send_telemetry(std::int64_t now) {
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
    sample = sync_.best();
    synced = sync_.synced();
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
  (void)now;
}

bool EndcapNode::loop_stalled(std::int64_t now) {
  if (config_.loop_progress == nullptr) return false;
  const std::uint64_t progress = config_.loop_progress->load(std::memory_order_relaxed);
  if (progress != loop_progress_seen_) {
    loop_progress_seen_ = progress;
    loop_progress_ns_ = now;
  }
  // Armed by the loop's first pass: the program starts its node before its loop.
  if (progress == 0) return false;
  const bool stalled = now - loop_progress_ns_ > to_ns(config_.loop_stall_timeout_s);
  if (stalled != loop_stall_reported_ && config_.log) {
    std::fprintf(stderr, "endcap %d: control loop %s\n", config_.endcap_id,
                 stalled ? "STALLED: DDS heartbeat withheld" : "progressing again: DDS heartbeat resumed");
  }
  loop_stall_reported_ = stalled;
  return stalled;
}

void EndcapNode::send_heartbeat(std::int64_t now) {
  if (loop_stalled(now)) return;  // a hung loop must look dead to the host
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
    hb.clock_synced(sync_.synced());
    hb.clock_offset_ns(sync_.best().offset_ns);
    hb.clock_round_trip_ns(sync_.best().round_trip_ns);
  }
  hb.host_lost(host_lost_.load());
  hb.host_loss_action(static_cast<std::uint8_t>(config_.host_loss));
  hb.loop_overruns(last_telemetry_.telemetry.overruns);
  dds_->heartbeat->write(&hb);
}

void EndcapNode::send_time_sync_request(std::int64_t) {
  m::TimeSyncRequest_ req;
  req.format_version(msgs::kFormatVersion);
  req.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  req.seq(++sync_sequence_);
  req.t1_ns(clock_.now_ns());  // as late as possible: the round trip starts here
  dds_->sync_request->write(&req);
}

void EndcapNode::on_time_sync_reply(Dds& d) {
  std::lock_guard guard(d.callback_mutex);
  if (d.closed || d.sync_reply == nullptr) return;  // stopping, or still starting (taken next time)
  m::TimeSyncReply_ reply;
  dds::SampleInfo info;
  while (d.sync_reply->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t t4 = clock_.now_ns();  // stamped before anything else
    if (!info.valid_data || reply.endcap_id() != config_.endcap_id) continue;
    if (reply.format_version() != msgs::kFormatVersion) continue;
    std::lock_guard lock(mutex_);
    sync_.add(reply.t1_ns(), reply.t2_ns(), reply.t3_ns(), t4);
  }
}

// Identity blob: "PID1" | version u32 | checksum u32 | id length u32 | id bytes (LE).
void EndcapNode::load_persisted_identity() {
  if (storage_ == nullptr) return;
  std::vector<std::uint8_t> bytes;
  if (storage_->read(kIdentityBlob, bytes) != StorageResult::ok) return;
  auto u32 = [&bytes](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(bytes[at + static_cast<std::size_t>(i)]) << (8 * i);
    return v;
  };
  if (bytes.size() < 16 || u32(0) != 0x31444950U || bytes.size() != 16 + u32(12) || u32(12) > 64) {
    if (config_.log) std::fprintf(stderr, "endcap %d: ignored a malformed %s blob\n", config_.endcap_id, kIdentityBlob);
    return;
  }
  std::lock_guard lock(mutex_);
  active_.policy_version = u32(4);
  active_.checksum = u32(8);
  active_.policy_id.assign(bytes.begin() + 16, bytes.end());
}

void EndcapNode::persist_identity() {
  if (storage_ == nullptr) return;
  const ActivePolicy a = active_policy();
  std::vector<std::uint8_t> bytes;
  auto u32 = [&bytes](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  u32(0x31444950U);
  u32(a.policy_version);
  u32(a.checksum);
  u32(static_cast<std::uint32_t>(a.policy_id.size()));
  bytes.insert(bytes.end(), a.policy_id.begin(), a.policy_id.end());
  const StorageResult r = storage_->write(kIdentityBlob, bytes);
  if (r != StorageResult::ok && config_.log) {
    std::fprintf(stderr, "endcap %d: cannot persist policy identity: %s\n", config_.endcap_id, to_string(r));
  }
}

}  // namespace tensegrity::fw::comms

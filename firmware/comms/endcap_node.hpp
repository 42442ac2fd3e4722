// SPDX-License-Identifier: Apache-2.0
// The end cap's DDS node: implements app::HostLink for the control loop and talks
// to the host over DDS on its own threads. The loop only ever touches the
// mailboxes (lock-free, no allocation); a slow or silent network therefore never
// delays a control cycle, it only delays what the node sends or hands over.
//
// The node validates policy tables (policy_wire.hpp + version), hands good ones
// to the loop, and acknowledges once the loop has taken them (Telemetry's
// table_ack_sequence); the loop's housekeeping persists them (app::PolicyStore),
// the node persists the policy's identity (id, version, checksum) so the version
// check survives a reboot. Commands are acknowledged; a start's host time is
// mapped to loop time through the time-sync estimate.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "firmware/app/host_link.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/comms/clock_sync.hpp"
#include "firmware/comms/policy_wire.hpp"
#include "firmware/hal/clock.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw::comms {

// The lockstep start grid in loop periods (start_grid_ns = this x the period):
// 200 ms at 1 kHz. A 50 ms grid failed (tables 1-2 ticks apart) when the 2-core
// host ran other real-time work at load 30 and time-sync errors exceeded 25 ms.
inline constexpr std::int64_t kLockstepStartGridPeriods = 200;

enum class HostLossAction : std::uint8_t { continue_gait = 0, stop = 1 };
const char* to_string(HostLossAction action);
// "continue" | "stop"; throws std::invalid_argument naming the accepted values.
HostLossAction parse_host_loss_action(const std::string& text);

struct EndcapNodeConfig {
  int endcap_id = 0;
  int domain = 42;
  PolicyExpectations expect{};  // endcap_id is overwritten with `endcap_id`
  double telemetry_rate_hz = 100.0;
  double heartbeat_rate_hz = 5.0;
  double time_sync_interval_s = 0.2;
  // No host heartbeat for this long (after one was seen) is a lost host.
  double host_timeout_s = 1.0;
  HostLossAction host_loss = HostLossAction::continue_gait;
  double loop_ack_timeout_s = 2.0;
  // A command issued longer ago than this (host time) is a replay from a writer's
  // history, not an order: ignored.
  double command_max_age_s = 5.0;
  bool log = true;  // one line per event to stderr
  // Lockstep (loop time = SYNC count x period, kept by whoever sends SYNC): host
  // time maps to loop time only while the SYNCs pause, so a start is placed a
  // whole number of these grid steps after the loop's last cycle: the host time
  // since that cycle, rounded. A HIL that pauses its SYNCs and aims the start at a
  // whole number of grid steps after the last one gets every end cap on the same
  // SYNC with table time exactly 0, as long as each end cap's mapping error (time
  // sync, wake-up latency: milliseconds on a loaded host) stays under half a
  // step. 0: no grid (a free-running loop maps host time directly).
  std::int64_t start_grid_ns = 0;
  // Fault injection (HIL): while *link_cut is true the participant's transport
  // drops every datagram in and out (msgs/link_cut_transport.hpp). Null: never cut.
  const std::atomic<bool>* link_cut = nullptr;
  // Watchdog: the control loop's progress counter (bumped by the loop thread every
  // pass, a lockstep wait for SYNC included). When it stands still for
  // loop_stall_timeout_s the node withholds its heartbeat, so the host sees a hung
  // loop as a silent end cap. Null: no watchdog.
  const std::atomic<std::uint64_t>* loop_progress = nullptr;
  double loop_stall_timeout_s = 0.5;
};

// Checks rates and timeouts; throws std::invalid_argument naming the field.
void validate(const EndcapNodeConfig& config);

struct ActivePolicy {
  std::string policy_id;  // empty: none known
  std::uint32_t policy_version = 0;
  std::uint32_t checksum = 0;
};

class EndcapNode final : public app::HostLink {
 public:
  // `storage` (may be null) keeps the active policy's identity across reboots.
  EndcapNode(const EndcapNodeConfig& config, Clock& clock, Storage* storage);
  ~EndcapNode() override;
  EndcapNode(const EndcapNode&) = delete;
  EndcapNode& operator=(const EndcapNode&) = delete;

  // Creates the participant and starts the node's thread; throws msgs::DdsError.
  void start();
  void stop() noexcept;

  // app::HostLink, called by the control loop's thread only.
  bool try_take_table(app::HostTable& out) noexcept override;
  bool try_take_command(app::HostCommand& out) noexcept override;
  void publish(const app::Telemetry& telemetry) noexcept override;

  // For logs and tests (any thread).
  ActivePolicy active_policy() const;
  ClockSample clock_sample() const;
  bool clock_synced() const;
  bool host_lost() const { return host_lost_.load(); }

 private:
  struct Dds;
  struct StampedTelemetry {
    app::Telemetry telemetry;
    std::int64_t local_ns = 0;  // node clock when the loop published it
  };

  void run();
  void service(std::int64_t now_ns);
  void handle_tables(std::int64_t now_ns);
  void finish_pending_table(std::int64_t now_ns);
  void handle_commands(std::int64_t now_ns);
  void handle_host_heartbeats(std::int64_t now_ns);
  void check_host_loss(std::int64_t now_ns);
  void send_telemetry(std::int64_t now_ns);
  void send_heartbeat(std::int64_t now_ns);
  void send_time_sync_request(std::int64_t now_ns);
  void on_time_sync_reply(Dds& dds);  // DDS listener thread
  void send_policy_ack(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text);
  void load_persisted_identity();
  void persist_identity();
  void wake();

  EndcapNodeConfig config_;
  Clock& clock_;
  Storage* storage_;
  std::unique_ptr<Dds> dds_;

  // Loop <-> node hand-over.
  app::SpscRing<app::HostTable, 4> tables_;
  app::SpscRing<app::HostCommand, 16> commands_;
  app::LatestValue<StampedTelemetry> telemetry_in_;

  // Node thread state.
  StampedTelemetry last_telemetry_{};
  bool loop_seen_ = false;
  std::deque<PolicyTableMsg> inbox_;
  bool table_pending_ = false;
  PolicyTableMsg pending_msg_;
  std::uint32_t pending_loop_sequence_ = 0;
  std::int64_t pending_since_ns_ = 0;
  std::uint32_t loop_sequence_ = 0;
  bool have_last_ack_ = false;
  std::uint32_t last_ack_upload_sequence_ = 0;
  PolicyReason last_ack_reason_ = PolicyReason::accepted;
  std::string last_ack_text_;
  struct RecentCommand {
    std::uint64_t issued = 0;
    std::uint32_t seq = 0;
    CommandReason reason = CommandReason::accepted;
  };
  std::deque<RecentCommand> recent_commands_;  // a retry gets the first answer again
  void send_command_ack(std::uint32_t seq, CommandReason reason);
  std::int64_t last_host_heartbeat_ns_ = 0;
  bool host_seen_ = false;
  std::uint32_t telemetry_sequence_ = 0;
  std::uint32_t heartbeat_sequence_ = 0;
  std::uint32_t sync_sequence_ = 0;
  std::int64_t next_telemetry_ns_ = 0;
  std::int64_t next_heartbeat_ns_ = 0;
  std::int64_t next_sync_ns_ = 0;
  std::uint64_t refused_format_ = 0;
  bool link_was_cut_ = false;
  std::int64_t started_ns_ = 0;  // node clock at start(): older commands are history
  void report_link_cut();
  bool loop_stalled(std::int64_t now_ns);  // the watchdog; logs changes
  std::uint64_t loop_progress_seen_ = 0;
  std::int64_t loop_progress_ns_ = 0;  // node clock when the counter last moved
  bool loop_stall_reported_ = false;

  mutable std::mutex mutex_;  // guards active_, sync_ (listener thread vs node thread)
  ActivePolicy active_;
  ClockSyncEstimator sync_;
  std::atomic<bool> host_lost_{false};

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace tensegrity::fw::comms

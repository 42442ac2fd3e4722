// SPDX-License-Identifier: Apache-2.0
// The end cap's DDS node: implements app::HostLink for the control loop and talks
// to the host over DDS on its own threads. The loop only ever touches the
// mailboxes and two counters (lock-free, no allocation); a slow or silent network
// therefore never delays a control cycle, it only delays what the node sends or
// hands over.
//
// Threads and files:
// - the node thread (endcap_node.cpp: service) runs policy tables
//   (node_tables.cpp), telemetry, heartbeats and host loss (node_status.cpp),
//   time-sync requests (node_time_sync.cpp) and, when no host hears this end cap
//   while it hears them, a new participant (node_rejoin.cpp);
// - Fast DDS's receive thread runs commands (node_commands.cpp: an emergency stop
//   is latched there, never waiting behind a table being stored) and time-sync
//   replies.
// A table is stored with its identity as one durable record (app::PolicyStore)
// before it reaches the loop, and "accepted" is acked once the loop took it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>

#include "firmware/app/host_link.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/comms/wire/clock_sync.hpp"
#include "firmware/comms/logic/command_gate.hpp"
#include "firmware/comms/node/node_config.hpp"
#include "firmware/comms/wire/policy_wire.hpp"
#include "firmware/comms/logic/start_readiness.hpp"
#include "firmware/comms/logic/start_time.hpp"
#include "firmware/comms/logic/time_sync_client.hpp"
#include "firmware/hal/clock.hpp"

namespace tensegrity::fw::comms {

using ActivePolicy = app::StoredIdentity;  // id empty: none known

class EndcapNode final : public app::HostLink {
 public:
  // Tables received but not yet judged; a table arriving when it is full is
  // answered loop_busy ("inbox full") at once and dropped: the uploader re-sends.
  static constexpr std::size_t kInboxCapacity = 8;

  // `store` (may be null) keeps the active table and its identity across reboots,
  // as one record; its current() record is the active policy at start.
  EndcapNode(const EndcapNodeConfig& config, Clock& clock, app::PolicyStore* store);
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
  std::uint32_t emergency_stops() const noexcept override { return estops_.load(std::memory_order_acquire); }
  std::uint32_t host_loss_stops() const noexcept override { return host_loss_stops_.load(std::memory_order_acquire); }
  // Any thread (the program's housekeeping reads it for --stats-json).
  app::LinkEvents link_events() const noexcept override;

  // For logs and tests (any thread).
  ActivePolicy active_policy() const;
  ClockSample clock_sample() const;
  bool clock_synced() const;
  bool host_lost() const { return host_lost_.load(); }
  std::uint64_t rejoins() const { return rejoins_.load(std::memory_order_relaxed); }
  TimeSyncCounters time_sync_counters() const;

 private:
  struct Dds;
  struct StampedTelemetry {
    app::Telemetry telemetry;
    std::int64_t local_ns = 0;  // node clock when the loop published it
  };
  // The table on its way to the loop: stored, handed over, not yet echoed.
  struct InFlight {
    bool active = false;
    bool answered = false;  // loop_busy already sent (the loop was slow)
    PolicyTableMsg msg;
    app::StoredIdentity identity;
    core::EndcapTable table{};
    std::uint32_t loop_sequence = 0;
    std::int64_t since_ns = 0;
  };
  struct LastAnswer {
    bool valid = false;
    std::uint32_t upload_sequence = 0;
    std::uint64_t digest = 0;
    PolicyReason reason = PolicyReason::accepted;
    std::string text;
  };

  // endcap_node.cpp: the node thread.
  std::unique_ptr<Dds> make_dds();  // throws msgs::DdsError
  void run();
  void service(std::int64_t now_ns);
  void wake();
  // node_tables.cpp
  void handle_tables(std::int64_t now_ns);
  void take_tables(Dds& dds);
  void judge_table(const PolicyTableMsg& msg, std::int64_t now_ns);
  void hand_over(const PolicyTableMsg& msg, const core::EndcapTable& table, std::int64_t now_ns);
  void finish_in_flight(std::int64_t now_ns);
  bool commit(const core::EndcapTable& table, const app::StoredIdentity& identity, std::string& error);
  void send_policy_ack(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text);
  // node_commands.cpp (Fast DDS receive thread)
  void on_commands(Dds& dds);
  CommandReason act_on(const CommandSample& c, WireCommandKind kind);
  void send_command_ack(Dds& dds, std::uint32_t seq, CommandReason reason);
  // node_status.cpp
  void handle_host_heartbeats(Dds& dds, std::int64_t now_ns);
  void check_host_loss(std::int64_t now_ns);
  bool loop_alive(std::int64_t now_ns);  // the loop-progress watchdog; logs changes
  void send_telemetry();
  void send_heartbeat(std::int64_t now_ns);
  void report_link_cut();
  void apply_mute_fault();
  // node_rejoin.cpp
  void note_host_heartbeat(std::uint16_t heard_endcaps, std::int64_t now_ns);
  void check_heard(std::int64_t now_ns);
  void note_host_lost();
  void rejoin_unheard(const char* what, std::int64_t unheard_ns, const char* then);
  void rejoin();
  void retire() noexcept;
  void pair_participants(bool paired) noexcept;
  // node_time_sync.cpp
  void send_time_sync_request();
  void report_if_unsynced();
  void on_time_sync_reply(Dds& dds);  // DDS listener thread
  void log(const char* format, ...) const __attribute__((format(printf, 2, 3)));

  EndcapNodeConfig config_;
  Clock& clock_;
  app::PolicyStore* store_;
  std::unique_ptr<Dds> dds_;
  // After a rejoin, the previous participant, still listening until a host hears
  // the new one (node_rejoin.cpp). Node thread only.
  std::unique_ptr<Dds> retiring_;

  // Loop <-> node hand-over.
  app::SpscRing<app::HostTable, 4> tables_;
  app::SpscRing<app::HostCommand, 16> commands_;  // producer: the command listener only
  app::LatestValue<StampedTelemetry> telemetry_in_;
  // The loop's clock and readiness for the command listener, its own copy: a start
  // is mapped and judged on the receive thread, and the node thread's last telemetry
  // may be many loop cycles old there (lockstep runs its cycles faster than the node
  // wakes).
  struct LoopPoint {
    LoopClockPoint clock;
    LoopReadiness ready;
  };
  app::LatestValue<LoopPoint> loop_in_;
  std::atomic<std::uint32_t> estops_{0};
  // Drawn at start, never 0 (a host's value): names this life's estop count on the
  // wire, so a clear-fault that saw an earlier life's count cannot match.
  const std::uint32_t life_id_ = (std::random_device{}() | 1U);
  std::atomic<std::uint32_t> host_loss_stops_{0};

  // Node thread state.
  StampedTelemetry last_telemetry_{};
  bool loop_seen_ = false;
  std::deque<PolicyTableMsg> inbox_;  // at most kInboxCapacity
  InFlight in_flight_;
  LastAnswer last_answer_;
  std::uint32_t loop_sequence_ = 0;
  core::EndcapTable active_table_{};  // what the store holds, to restore after a refusal
  bool have_active_table_ = false;
  std::int64_t last_host_heartbeat_ns_ = 0;
  bool host_seen_ = false;
  std::int64_t started_ns_ = 0;  // node clock at start(): the boot grace runs from here
  // Whether any host hears this end cap (node_rejoin.cpp), node clock.
  std::int64_t hearing_since_ns_ = 0;       // host heartbeats arriving without a loss since
  std::int64_t named_ns_ = 0;               // a host heartbeat last named this end cap
  std::int64_t others_named_ns_ = 0;        // ... named another end cap
  std::int64_t others_named_since_ns_ = 0;  // ... and had, without a gap, since
  std::int64_t participant_since_ns_ = 0;   // this participant was made
  bool current_hears_host_ = false;         // dds_ has taken a host heartbeat
  bool remake_pending_ = false;             // making a new participant failed ...
  std::int64_t next_remake_ns_ = 0;         // ... and is tried again then,
  std::int64_t remake_retry_ns_ = 0;        // ... after this (doubling)
  std::uint32_t remake_failures_ = 0;
  double rejoin_wait_s_ = 0.0;  // doubles while rejoins go unanswered
  std::uint32_t telemetry_sequence_ = 0;
  std::uint32_t heartbeat_sequence_ = 0;
  std::uint32_t sync_sequence_ = 0;
  std::int64_t next_telemetry_ns_ = 0;
  std::int64_t next_heartbeat_ns_ = 0;
  std::int64_t next_sync_ns_ = 0;
  std::int64_t next_unsynced_report_ns_ = 0;
  std::uint64_t refused_format_ = 0;
  bool link_was_cut_ = false;
  std::uint32_t mutes_seen_ = 0;
  std::uint64_t loop_progress_seen_ = 0;
  std::int64_t loop_progress_ns_ = 0;  // node clock when the counter last moved
  bool loop_stall_reported_ = false;

  // Command listener state: guarded by receive_mutex_ (Fast DDS may call from more
  // than one receive thread, and after a rejoin two participants listen).
  std::mutex receive_mutex_;
  CommandGate gate_;
  StartTimeMapper start_mapper_;
  LoopPoint loop_point_{};
  bool loop_point_valid_ = false;

  // Shared between the node thread and the listeners.
  mutable std::mutex mutex_;  // guards the members below
  ActivePolicy active_;
  TimeSyncClient sync_;
  std::atomic<bool> host_lost_{false};
  // What the log says in words, counted (written by the node thread only).
  std::atomic<std::uint64_t> host_losses_{0}, host_returns_{0}, link_cuts_{0}, loop_stalls_{0}, rejoins_{0};

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace tensegrity::fw::comms

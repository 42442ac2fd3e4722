// SPDX-License-Identifier: Apache-2.0
// The end cap's DDS node: implements app::HostLink for the control loop and talks
// to the host over DDS on its own threads. The loop only ever touches the
// mailboxes and counters (lock-free, no allocation); a slow or silent network
// therefore never delays a control cycle, it only delays what the node sends or
// hands over.
//
// The node is a shell that wires DDS readers and writers to small parts, each
// deciding one job without DDS (unit-tested with fake time and samples):
// - TableInbox (table_inbox.hpp): policy tables judged, stored, handed to the
//   loop and acknowledged;
// - CommandHandler (command_handler.hpp): commands judged and acted on at once, on
//   Fast DDS's receive thread (an emergency stop never waits behind a table);
// - HostWatch (host_watch.hpp): host heartbeats, host loss and its stop;
// - RejoinWatch (rejoin_watch.hpp): when no host hears this end cap while it hears
//   them, a new participant;
// - LoopWatch, LinkFaultWatch (loop_watch.hpp): the loop-progress watchdog and
//   injected link faults;
// - SendSchedule (send_schedule.hpp) and SharedTimeSync (shared_time_sync.hpp):
//   what is sent when, and the clock estimate both threads read.
// The node thread (endcap_node.cpp: run) polls the parts; the receive thread
// (node_listeners.cpp) runs commands and time-sync replies.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>

#include "firmware/app/host_link.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/comms/node/command_handler.hpp"
#include "firmware/comms/node/host_watch.hpp"
#include "firmware/comms/node/loop_watch.hpp"
#include "firmware/comms/node/node_config.hpp"
#include "firmware/comms/node/node_log.hpp"
#include "firmware/comms/node/rejoin_watch.hpp"
#include "firmware/comms/node/send_schedule.hpp"
#include "firmware/comms/node/shared_time_sync.hpp"
#include "firmware/comms/node/table_inbox.hpp"
#include "firmware/hal/clock.hpp"

namespace tensegrity::fw::comms {

struct NodeFacts;
struct NodeParticipant;
class Participants;

class EndcapNode final : public app::HostLink {
 public:
  static constexpr std::size_t kInboxCapacity = TableInbox::kCapacity;

  // `store` (may be null) keeps the active table and its identity across reboots,
  // as one record; its current() record is the active policy at start.
  // Throws std::invalid_argument naming a bad field of `config`.
  EndcapNode(const EndcapNodeConfig& config, Clock& clock, app::PolicyStore* store);
  ~EndcapNode() override;
  EndcapNode(const EndcapNode&) = delete;
  EndcapNode& operator=(const EndcapNode&) = delete;

  // Creates the participant and starts the node's thread; throws msgs::DdsError.
  void start();
  void stop() noexcept;

  // app::HostLink, called by the control loop's thread only.
  bool try_take_table(app::HostTable& out) noexcept override { return tables_.take(out); }
  bool try_take_command(app::HostCommand& out) noexcept override { return commands_.take(out); }
  void publish(const app::Telemetry& telemetry) noexcept override;
  std::uint32_t emergency_stops() const noexcept override { return commands_.estops(); }
  std::uint32_t host_loss_stops() const noexcept override { return host_.stops(); }
  // Any thread (the program's housekeeping reads it for --stats-json).
  app::LinkEvents link_events() const noexcept override;

 private:
  struct StampedTelemetry {
    app::Telemetry telemetry;
    std::int64_t local_ns = 0;  // node clock when the loop published it
  };

  // endcap_node.cpp: the node thread.
  void run();
  void wake();
  void service(std::int64_t now_ns);
  void take_samples(NodeParticipant& p, std::int64_t now_ns);
  void send_reports(std::int64_t now_ns);
  void rejoin();
  NodeFacts facts() const;
  // node_listeners.cpp: the participant and its listeners.
  std::unique_ptr<NodeParticipant> make_participant();  // throws msgs::DdsError
  void on_commands(NodeParticipant& p);                 // Fast DDS's receive thread
  void on_time_sync_reply(NodeParticipant& p);          // Fast DDS's receive thread

  EndcapNodeConfig config_;
  Clock& clock_;
  NodeLog log_;
  SharedTimeSync sync_;
  CommandHandler commands_;
  TableInbox tables_;
  HostWatch host_;
  RejoinWatch rejoin_;
  LoopWatch loop_watch_;
  LinkFaultWatch faults_;
  SendSchedule schedule_;
  std::unique_ptr<Participants> participants_;

  app::LatestValue<StampedTelemetry> telemetry_in_;  // from the loop
  // Node thread state.
  StampedTelemetry last_telemetry_{};
  bool loop_seen_ = false;
  std::uint32_t telemetry_sequence_ = 0;
  std::uint32_t heartbeat_sequence_ = 0;

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// The host's end of the DDS link, used by every ground tool and by the HIL
// launcher: one participant with the host's writers (policy tables, commands,
// host heartbeat, time-sync replies) and readers (acks, telemetry, end-cap
// heartbeats, time-sync requests). It answers time-sync requests from the DDS
// receive thread itself, so the host side of the exchange adds no queueing.
//
// Host time is this machine's CLOCK_MONOTONIC: every ground tool on the host
// shares it, so an end cap's offset stays valid from one tool to the next.
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "firmware/comms/wire/estop_count.hpp"
#include "tensegrity_msgs/msg/Command.h"
#include "tensegrity_msgs/msg/CommandAck.h"
#include "tensegrity_msgs/msg/Heartbeat.h"
#include "tensegrity_msgs/msg/PolicyAck.h"
#include "tensegrity_msgs/msg/PolicyTable.h"
#include "tensegrity_msgs/msg/Telemetry.h"

namespace tensegrity::ground {

namespace msg = tensegrity_msgs::msg::dds_;

inline constexpr int kEndcapCount = 12;
inline constexpr std::uint16_t kAllEndcaps = 0x0FFF;

struct StationOptions {
  int domain = 42;
  std::string name = "ground";
  // Observers (tests, a second monitor) can stay silent so that they do not keep
  // the end caps' host-loss watchdog satisfied.
  bool publish_heartbeat = true;
  double heartbeat_rate_hz = 5.0;
  bool serve_time = true;
  // DDS Security: the ground enclave of a keystore (msgs/security.hpp); empty: unsecured.
  std::filesystem::path enclave_dir;
};

struct EndcapStatus {
  bool seen = false;                   // a heartbeat arrived
  std::int64_t heartbeat_host_ns = 0;  // host clock at its arrival
  msg::Heartbeat_ heartbeat;
  bool have_telemetry = false;
  std::int64_t telemetry_host_ns = 0;
  msg::Telemetry_ telemetry;
  std::uint64_t telemetry_count = 0;
  std::uint64_t telemetry_gaps = 0;  // samples missing by sequence number
  std::uint64_t refused = 0;         // samples with another message-format version
  // Emergency stops the end cap has taken as this station heard them (heartbeats and
  // acks of its own commands): what a clear-fault from it says it has seen. Within a
  // life the highest count wins (a heartbeat read before an estop may arrive after
  // its ack); a new life replaces it.
  fw::comms::EstopCount estops;
  // Lives this end cap has left, latest first (0: none). A program draws its life
  // when it starts, so a life never comes back: a heartbeat or ack of one that
  // arrives late is stale and is dropped (it would show the dead program's fault
  // and count until the next heartbeat).
  std::array<std::uint32_t, 4> left_lives{};
  std::uint64_t stale_life_samples = 0;
  // At the snapshot: this station's policy-table and command writers are matched
  // with this end cap's readers (Station::reached). Heard and not reached: what it
  // writes, an estop too, goes to nobody yet.
  bool reached = false;
};

class Station {
 public:
  explicit Station(const StationOptions& options);
  ~Station();
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  static std::int64_t now_ns();

  void write_policy(const msg::PolicyTable_& table);
  void write_command(const msg::Command_& command);

  // Acks received since the last call (any thread may wait, one should take).
  std::vector<msg::PolicyAck_> take_policy_acks();
  std::vector<msg::CommandAck_> take_command_acks();
  // Return when an ack of that kind is waiting or at `deadline_ns` (host clock). Each
  // waits for its own kind: a station that never takes policy acks (the operator
  // console's) must not have its command waits woken for good by one.
  void wait_for_policy_acks(std::int64_t deadline_ns);
  void wait_for_command_acks(std::int64_t deadline_ns);
  // Acks nobody takes are kept up to this many of each kind (the oldest dropped).
  static constexpr std::size_t kMaxPendingAcks = 1024;

  std::array<EndcapStatus, kEndcapCount> snapshot() const;
  // An end cap's estop count heard in an ack of a command this station sent
  // (send_command calls it; acks of other tools' commands, or history, do not count).
  void note_estops(int endcap, const fw::comms::EstopCount& heard);
  // Host time at which this station's participant was made: end caps are discovered
  // in the seconds after it (a clear-fault waits for them up to kClearHearWaitS).
  std::int64_t started_ns() const { return started_ns_; }
  // The end caps whose heartbeat arrived at most `fresh_s` before `now_ns`, as a mask.
  // This station's own heartbeat names them (kHeardFreshS), so that an end cap that
  // hears the host but is not heard can tell and join again.
  std::uint16_t heard(std::int64_t now_ns, double fresh_s) const;
  static constexpr double kHeardFreshS = 2.0;
  // The end caps (a bit each) whose policy-table and command readers this station's
  // writers are matched with: what it writes reaches them (msgs/matched_readers.hpp).
  std::uint16_t reached() const;
  // True once every end cap in `mask` sent a heartbeat (and, with `synced`, says
  // its clock is synchronized) and is reached, and, when this station is a host
  // (publish_heartbeat), hears a host: an end cap that has lost its host stops what
  // it is told to start (host_lost), and a fresh station's orders can reach it
  // before its heartbeat does. False at the deadline.
  bool wait_for_endcaps(std::uint16_t mask, bool synced, std::int64_t deadline_ns) const;
  // Called from the DDS receive thread for every valid telemetry sample, with the
  // host clock at arrival. Set before samples are expected; keep it short.
  void on_telemetry(std::function<void(const msg::Telemetry_&, std::int64_t)> callback);

  // Time-sync requests answered so far (for tests and the status line).
  std::uint64_t time_sync_replies() const;
  // Reports refused because their end cap id is not the one their writer publishes
  // for (msgs/endcap_writers.hpp): an end cap's identity speaking for another.
  std::uint64_t impostor_samples() const;

 private:
  struct Dds;
  friend struct StationListeners;
  void heartbeat_loop();

  StationOptions options_;
  std::int64_t started_ns_ = now_ns();
  std::unique_ptr<Dds> dds_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::array<EndcapStatus, kEndcapCount> status_{};
  std::vector<msg::PolicyAck_> policy_acks_;
  std::vector<msg::CommandAck_> command_acks_;
  std::function<void(const msg::Telemetry_&, std::int64_t)> telemetry_callback_;
  std::uint64_t sync_replies_ = 0;
  std::uint64_t impostor_samples_ = 0;
  bool stopping_ = false;
  std::condition_variable stop_cv_;
  std::unique_ptr<std::thread> heartbeat_thread_;
};

}  // namespace tensegrity::ground

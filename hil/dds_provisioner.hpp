// SPDX-License-Identifier: Apache-2.0
// The DDS provisioner: the end caps run their DDS link to this host, on a domain
// of the run's own (DomainLease), and get the policy and the start the way a real
// robot does: `ground::upload` (the code path of `tensegrity upload`: one table
// per end cap, acknowledged, re-sent until acknowledged) and a start command with
// a common host time (`tensegrity start`). Both happen while the stepper holds
// the end caps with their drives enabled and physics frozen (WorldStepper::hold);
// the start handshake turns the host time into physics step 0 (start_handshake.hpp).
//
// A killed end cap that is started again plays its stored table in phase:
//  - lockstep: it gets --start-on-boot and the stepper's start gate lets it
//    through at a policy-period boundary (table time 0 on that exact tick);
//  - real time: a supervisor thread waits for it to come back (heartbeat, clock
//    synchronized, drives enabled, idle) and sends it the run's original start
//    time; an end cap started "in the past" plays its table that far along.
// Unless the operator stopped the run: once the launcher has heard any end cap take
// an emergency stop during the run, every later restart is left idle in both modes,
// for the rest of the run; starting it again is the operator's. Lockstep decides at
// the spawn, so an end cap started on boot is stopped by the launcher if the estop
// is heard just after (dds_provisioner_rejoin.cpp, docs/guide/hil.md).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "firmware/comms/wire/policy_wire.hpp"
#include "firmware/comms/wire/start_grid.hpp"
#include "ground/station.hpp"
#include "hil/dds_domain.hpp"
#include "hil/provisioner.hpp"
#include "hil/retry_backoff.hpp"
#include "hil/start_handshake.hpp"
#include "hil/world_stepper.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {

struct DdsProvisionerConfig {
  int domain = -1;                 // -1: lease a free one (DomainLease)
  std::string host_loss = "stop";  // the end caps' --host-loss
  // DDS Security: the keystore the HIL's ground station and end caps take their
  // enclaves from (created if missing). Empty: unsecured (`hil --insecure`).
  std::filesystem::path keystore;
  StepperMode mode = StepperMode::lockstep;
  // Every end cap's heartbeat with a synchronized clock. Usually 1-6 s; a real-time
  // HIL on 2 cores (1.3 of them at SCHED_FIFO) took up to 14.4 s (docs/guide/hil.md).
  double discovery_timeout_s = 45.0;
  double upload_timeout_s = 10.0;
  double command_timeout_s = 5.0;
  // Lockstep: physics step 0 is this many SYNCs after the freeze: a whole number of
  // the end caps' start grid (firmware/comms/wire/start_grid.hpp), the loops being frozen meanwhile.
  std::int64_t start_after_ticks = 2 * fw::comms::kLockstepStartGridPeriods;
  // Real time: the start's host time is this far ahead of the command.
  // Real time: the start is placed this far ahead. On this 2-core host the real-time
  // emulator and twelve end-cap loops take about 1.5 cores at SCHED_FIFO and the end
  // caps' DDS threads are ordinary threads: 0.5 s was missed now and then (an ack
  // waited a 0.5 s retry), 1.5 s with a software-rendering browser open (2.6 s).
  double realtime_lead_s = 3.0;
  // A start is placed through each end cap's time sync, good to half its round
  // trip: before sending one, wait (at most sync_settle_timeout_s) until every end
  // cap addressed reports a round trip within this.
  double max_sync_round_trip_s = 0.002;
  double sync_settle_timeout_s = 5.0;
  double rejoin_sync_settle_timeout_s = 1.0;  // a restarted end cap: every second out of the gait counts
};

class DdsProvisioner final : public Provisioner {
 public:
  // Creates the host's DDS participant at once (before the end caps start, so
  // discovery runs during their boot; and on the caller's scheduling class).
  DdsProvisioner(const sim::Robot& robot, const sim::Policy& policy, const std::filesystem::path& policy_file,
                 const DdsProvisionerConfig& config);
  ~DdsProvisioner() override;

  std::string name() const override;
  LinkTiming link_timing() const override;
  std::vector<std::string> endcap_arguments(int endcap, bool restart) const override;
  bool needs_hold() const override { return true; }
  void provision(const ProcessLauncher&) override {}
  void start(const ProcessLauncher&) override {}
  void deliver(StartHandshake& handshake) override;
  void begin_run() override;
  void end_run() override;
  bool dds_link() const override { return true; }
  void on_restart(int endcap) override;
  std::vector<std::string> log() const override;
  std::vector<HostHearing> host_hearing() const override;

  int domain() const { return lease_.domain(); }

 private:
  // deliver()'s steps.
  void await_endcaps(std::uint16_t mask, std::int64_t deadline_ns);
  bool wait_or_rejoin(std::uint16_t mask, std::int64_t deadline_ns);
  double upload_policy(const fw::comms::PolicyIdentity& identity, double& total_s);
  void clear_faults_or_fail(std::uint16_t mask);
  std::int64_t place_start(StartHandshake& handshake, std::string& how);
  void send_start(std::uint16_t mask, std::int64_t start_ns);
  void supervise();
  // The supervisor's step for one restarted end cap (restarted at host time `since`).
  void rejoin(int endcap, std::int64_t since, const ground::EndcapStatus& status);
  // Lockstep's: stops an end cap started on boot if an estop is heard just after.
  void recall(int endcap, std::int64_t since, const ground::EndcapStatus& status);
  // Forgets a pending restart (if still the one of `since`), with a line for the log.
  void settle_restart(int endcap, std::int64_t since, const std::string& line);
  // An end cap that took an emergency stop: the first one seen (latched for the
  // run: never undone, not by a clear-fault nor an operator's start, see the
  // header), -1 if none has. Any thread.
  int operator_stop() const;
  int operator_stop(const std::array<ground::EndcapStatus, ground::kEndcapCount>& status) const;
  static void normal_priority();
  // The host's side of the link during a real-time run (dds_provisioner_link.cpp): an
  // end cap unheard for kUnheardAfterNs is logged, and again when it is heard, with how
  // long, so a lost or muted end cap is seen in the run's log. Supervisor thread only.
  void watch_link(const std::array<ground::EndcapStatus, ground::kEndcapCount>& status, std::int64_t now_ns);
  // End caps of `mask` that report a latched fault get one clear-fault (the
  // operator's `tensegrity clear-fault` before a start), logged; returns false if
  // one is still faulted by `deadline_ns`.
  bool clear_faults_before_start(std::uint16_t mask, std::int64_t deadline_ns);
  // Waits until every end cap of `mask` reports a time-sync round trip within
  // max_sync_round_trip_s, at most until `deadline_ns`; returns the worst one seen.
  double settle_time_sync(std::uint16_t mask, std::int64_t deadline_ns) const;
  void note(const std::string& line);

  const sim::Robot& robot_;
  const sim::Policy& policy_;
  std::string policy_id_;
  DdsProvisionerConfig config_;
  DomainLease lease_;
  ground::StationOptions station_options_;
  std::unique_ptr<ground::Station> station_;
  std::int64_t start_host_ns_ = 0;  // the run's start (host time of table time 0)

  mutable std::mutex mutex_;
  std::vector<std::string> log_;
  LinkTiming timing_;  // under mutex_
  // Per end cap: host time of a restart the supervisor still watches (0: none); real
  // time: not yet started; lockstep: started on boot, in its recall window.
  std::vector<std::int64_t> restarted_at_ns_;
  // Per end cap: its refusals of the supervisor's start (real time) or stop (lockstep's
  // recall: a stop is never held back, only its log lines thinned). The supervisor
  // thread's; end_run reads it after joining that thread.
  std::vector<RetryBackoff> retry_;
  std::atomic<bool> stopping_{false};
  std::thread supervisor_;
  std::int64_t run_begun_ns_ = 0;               // host clock at begin_run (the supervisor's start)
  std::int64_t run_ended_ns_ = 0;               // ... at end_run
  std::vector<std::int64_t> unheard_since_ns_;  // per end cap: its last heartbeat while unheard (0: heard)
  std::vector<HostHearing> hearing_;            // per end cap, closed spells; under mutex_
  // Lockstep, per end cap: the end cap whose estop kept its restart idle (-1: none).
  // Written by endcap_arguments (const for the launcher, but it decides here whether
  // the program gets --start-on-boot), read by on_restart, which the launcher calls
  // right after; both on the stepper's thread.
  mutable std::vector<int> withheld_by_;  // under mutex_
  mutable std::atomic<int> operator_stop_{-1};
};

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
#include "hil/dds_provisioner.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

#include "core/fault.hpp"
#include "core/table.hpp"
#include "ground/command.hpp"
#include "ground/keystore.hpp"
#include "ground/station.hpp"
#include "ground/status.hpp"
#include "ground/upload.hpp"
#include "hil/hil_error.hpp"
#include "hil/loop_rate.hpp"
#include "msgs/security.hpp"

namespace tensegrity::hil {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

}  // namespace

// Threads of this provisioner talk DDS; they must not inherit the emulator's
// SCHED_FIFO (they would compete with the stepper they wait for).
void DdsProvisioner::normal_priority() {
  sched_param p{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
}

DdsProvisioner::DdsProvisioner(const sim::Robot& robot, const sim::Policy& policy,
                               const std::filesystem::path& policy_file, const DdsProvisionerConfig& config)
    : robot_(robot),
      policy_(policy),
      policy_id_(policy_file.stem().string().substr(0, 64)),
      config_(config),
      lease_(config.domain),
      restarted_at_ns_(static_cast<std::size_t>(robot.endcap_count()), 0),
      retry_(static_cast<std::size_t>(robot.endcap_count()),
             config.mode == StepperMode::lockstep ? RetryBackoff(0, 0) : RetryBackoff()),
      withheld_by_(static_cast<std::size_t>(robot.endcap_count()), -1) {
  if (robot.endcap_count() > ground::kEndcapCount) {
    throw HilError("the DDS link addresses at most " + std::to_string(ground::kEndcapCount) + " end caps");
  }
  if (config_.host_loss != "continue" && config_.host_loss != "stop") {
    throw HilError("host loss '" + config_.host_loss + "': expected continue or stop");
  }
  if (policy_id_.empty()) policy_id_ = "policy";
  ground::StationOptions so;
  so.domain = lease_.domain();
  so.name = "tensegrity-hil";
  if (!config_.keystore.empty()) {
    try {
      if (ground::ensure_keystore(config_.keystore)) {
        std::fprintf(stderr, "hil: created DDS Security keystore %s\n", config_.keystore.c_str());
      }
    } catch (const std::exception& e) {
      throw HilError(std::string("DDS Security keystore: ") + e.what());
    }
    so.enclave_dir = msgs::enclave_dir(config_.keystore, msgs::enclave_name(msgs::Role::ground));
  }
  station_options_ = so;
  station_ = std::make_unique<ground::Station>(so);
}

DdsProvisioner::~DdsProvisioner() { end_run(); }

std::string DdsProvisioner::name() const {
  return "dds (domain " + std::to_string(lease_.domain()) + (config_.keystore.empty() ? ", unsecured" : ", secured") +
         ", upload + start command)";
}

std::vector<std::string> DdsProvisioner::endcap_arguments(int e, bool restart) const {
  std::vector<std::string> args{"--domain", std::to_string(lease_.domain()), "--dds-cut-signals", "--host-loss",
                                config_.host_loss};
  if (config_.keystore.empty()) {
    args.emplace_back("--insecure");
  } else {
    args.insert(args.end(), {"--keystore", config_.keystore.string()});
  }
  // Lockstep: the stepper's gate lets a restarted end cap through on a period
  // boundary, and start on boot makes that tick table time 0 (see the header);
  // unless the operator stopped the run: then it comes up idle (on_restart says so).
  if (restart && config_.mode == StepperMode::lockstep) {
    const int stopped_by = operator_stop();
    std::lock_guard lock(mutex_);
    if (e < static_cast<int>(withheld_by_.size())) withheld_by_[e] = stopped_by;
    if (stopped_by < 0) args.emplace_back("--start-on-boot");
  }
  return args;
}

void DdsProvisioner::note(const std::string& line) {
  std::lock_guard lock(mutex_);
  log_.push_back(line);
}

std::vector<std::string> DdsProvisioner::log() const {
  std::lock_guard lock(mutex_);
  return log_;
}

// 1. Everyone on the link with a synchronized clock (a start needs one).
// 2. The policy, as `tensegrity upload` sends it. Returns the slowest acknowledgement.
double DdsProvisioner::upload_policy(const fw::comms::PolicyIdentity& identity, double& total_s) {
  const auto tables = ground::policy_messages(policy_, robot_, identity, ground::random_sequence_base());
  ground::UploadOptions uo;
  uo.timeout_s = config_.upload_timeout_s;
  const ground::UploadReport upload = ground::upload(*station_, tables, uo);
  if (!upload.all_accepted()) {
    std::string why;
    for (const auto& r : upload.results) {
      if (r.accepted) continue;
      why += (why.empty() ? "" : "; ") + ("end cap " + std::to_string(r.endcap) + ": " +
                                          (r.acked ? "rejected (" + r.text + ")" : std::string("no acknowledgement")));
    }
    throw HilError("policy upload over DDS incomplete: " + why);
  }
  double worst_s = 0.0;
  for (const auto& r : upload.results) worst_s = std::max(worst_s, r.latency_s);
  total_s = upload.total_s;
  return worst_s;
}

// Real time: an end cap armed early in the boot may have latched a sensor
// timeout while the emulator was busy starting the others. Cleared, and said.
void DdsProvisioner::clear_faults_or_fail(std::uint16_t mask) {
  if (clear_faults_before_start(mask, ground::Station::now_ns() + core::seconds_to_ns(config_.command_timeout_s)))
    return;
  std::string why;
  const auto status = station_->snapshot();
  for (int e = 0; e < robot_.endcap_count(); ++e) {
    if (status[e].heartbeat.fault() != 0) {
      why +=
          (why.empty() ? "" : ", ") + std::to_string(e) + " (" + ground::fault_name(status[e].heartbeat.fault()) + ")";
    }
  }
  throw HilError("end cap(s) " + why +
                 " still faulted before the start (an emergency stop is left to the operator: tensegrity clear-fault)");
}

// 3. One start time for all. Lockstep: k ticks after the last SYNC (plus half the
// window in which the end caps ran it): each end cap rounds the host time since
// its last cycle to its start grid, so its mapping error (time sync, wake-up) may
// be up to half a grid step. Real time: a little ahead of now.
std::int64_t DdsProvisioner::place_start(StartHandshake& handshake, std::string& how) {
  if (config_.mode == StepperMode::lockstep) {
    const FrozenTick frozen = handshake.freeze(ground::Station::now_ns() + 10 * kNsPerS);
    how = "SYNC +" + std::to_string(config_.start_after_ticks) + " after the freeze (last tick answered in " +
          std::to_string((frozen.answered_ns - frozen.sent_ns) / 1000) + " us)";
    return frozen.sent_ns + config_.start_after_ticks * endcap_period_ns(robot_) +
           (frozen.answered_ns - frozen.sent_ns) / 2;
  }
  char in[48];
  std::snprintf(in, sizeof in, "in %.2f s", config_.realtime_lead_s);
  how = in;
  return ground::Station::now_ns() + core::seconds_to_ns(config_.realtime_lead_s);
}

void DdsProvisioner::send_start(std::uint16_t mask, std::int64_t start_ns) {
  ground::CommandOptions co;
  co.endcap_mask = mask;
  co.timeout_s = config_.command_timeout_s;
  const ground::CommandReport report = ground::send_command(*station_, ground::CommandKind::start, start_ns, co);
  if (!report.all_accepted()) {
    std::string why;
    for (const auto& r : report.results) {
      if (!r.accepted) why += (why.empty() ? "" : "; ") + ("end cap " + std::to_string(r.endcap) + ": " + r.text);
    }
    throw HilError("start command over DDS not accepted: " + why);
  }
  if (config_.mode == StepperMode::realtime && ground::Station::now_ns() >= start_ns) {
    double slowest_ms = 0.0;
    int slowest = -1;
    for (const auto& r : report.results) {
      if (r.latency_s * 1e3 > slowest_ms) slowest_ms = r.latency_s * 1e3, slowest = r.endcap;
    }
    throw HilError("start command acknowledged only after its start time (the link was too slow: end cap " +
                   std::to_string(slowest) + " acked after " + std::to_string(static_cast<int>(slowest_ms)) +
                   " ms, the lead was " + std::to_string(static_cast<int>(config_.realtime_lead_s * 1e3)) + " ms)");
  }
}

void DdsProvisioner::deliver(StartHandshake& handshake) {
  normal_priority();
  const int n = robot_.endcap_count();
  const auto mask = static_cast<std::uint16_t>((1U << n) - 1U);
  const std::int64_t t0 = ground::Station::now_ns();
  await_endcaps(mask, t0 + core::seconds_to_ns(config_.discovery_timeout_s));
  const std::int64_t t_found = ground::Station::now_ns();

  fw::comms::PolicyIdentity identity;
  identity.policy_id = policy_id_;
  identity.policy_version = static_cast<std::uint32_t>(std::time(nullptr));
  identity.robot = robot_.name;
  double upload_s = 0.0;
  const double worst_ack_s = upload_policy(identity, upload_s);
  clear_faults_or_fail(mask);

  // Once every clock is known well enough to place the start.
  const double settle_rt_ms =
      settle_time_sync(mask, ground::Station::now_ns() + core::seconds_to_ns(config_.sync_settle_timeout_s)) * 1e3;
  std::string how;
  const std::int64_t start_ns = place_start(handshake, how);
  send_start(mask, start_ns);
  start_host_ns_ = start_ns;
  // The time sync's quality: every process here reads the same clock, so each
  // end cap's offset estimate is its error.
  double worst_offset_ms = 0.0, worst_round_trip_ms = 0.0;
  for (const auto& s : station_->snapshot()) {
    if (!s.seen) continue;
    worst_offset_ms = std::max(worst_offset_ms, std::abs(static_cast<double>(s.heartbeat.clock_offset_ns())) * 1e-6);
    worst_round_trip_ms = std::max(worst_round_trip_ms, static_cast<double>(s.heartbeat.clock_round_trip_ns()) * 1e-6);
  }
  char line[512];
  std::snprintf(
      line, sizeof line,
      "dds: %d end caps on domain %d (%s) in %.0f ms; policy %s v%u uploaded in %.1f ms (slowest ack %.1f ms); "
      "start at host time %.6f s (%s); time sync at the start: worst round trip %.3f ms; at the end of "
      "the hold: worst offset %.3f ms, worst round trip %.3f ms",
      n, lease_.domain(), config_.keystore.empty() ? "UNSECURED, --insecure" : "secured, DDS Security",
      static_cast<double>(t_found - t0) * 1e-6, identity.policy_id.c_str(), identity.policy_version, upload_s * 1e3,
      worst_ack_s * 1e3, static_cast<double>(start_ns) * 1e-9, how.c_str(), settle_rt_ms, worst_offset_ms,
      worst_round_trip_ms);
  note(line);
  {
    std::lock_guard lock(mutex_);
    timing_ = LinkTiming{true, !config_.keystore.empty(), static_cast<double>(t_found - t0) * 1e-9, upload_s};
  }
  if (config_.mode == StepperMode::lockstep) {
    handshake.go_after_ticks(config_.start_after_ticks);
  } else {
    handshake.go_at(start_ns);
  }
}

bool DdsProvisioner::clear_faults_before_start(std::uint16_t mask, std::int64_t deadline_ns) {
  std::uint16_t faulted = 0;
  std::string which;
  for (int e = 0; e < ground::kEndcapCount; ++e) {
    const ground::EndcapStatus s = station_->snapshot()[e];
    // Telemetry (100 Hz) shows a fault latched since the last heartbeat (5 Hz): an end
    // cap refuses a start while one is latched (fault_latched), so none may be missed.
    const std::uint8_t fault =
        s.seen && s.heartbeat.fault() != 0 ? s.heartbeat.fault() : (s.have_telemetry ? s.telemetry.fault() : 0);
    if ((mask & (1U << e)) == 0 || !s.seen || fault == 0) continue;
    // An operator's stop is theirs to clear, never the launcher's (which sends none):
    // any estop this life took, also one latched on top of a milder first fault.
    if (fault == static_cast<std::uint8_t>(core::FaultCause::emergency_stop) || s.estops.count > 0) {
      note("dds: end cap " + std::to_string(e) +
           " took an emergency stop: left to the operator (tensegrity clear-fault)");
      return false;
    }
    faulted = static_cast<std::uint16_t>(faulted | (1U << e));
    which += (which.empty() ? "" : ", ") + std::to_string(e) + " (" + ground::fault_name(fault) + ")";
  }
  if (faulted == 0) return true;
  ground::CommandOptions co;
  co.endcap_mask = faulted;
  co.timeout_s = config_.command_timeout_s;
  const ground::CommandReport report = ground::send_command(*station_, ground::CommandKind::clear_fault, 0, co);
  if (!report.all_accepted()) {
    note("dds: clear-fault for end cap(s) " + which + " not taken by all:\n" + ground::format_command_report(report));
    return false;
  }
  note("dds: end cap(s) " + which + " had latched a fault before the start: cleared (clear-fault)");
  // The heartbeat (5 Hz) says when it took; the drives may take a few cycles more.
  for (;;) {
    bool clear = true;
    const auto status = station_->snapshot();
    for (int e = 0; e < ground::kEndcapCount; ++e) {
      if ((faulted & (1U << e)) == 0) continue;
      clear = clear && status[e].heartbeat.fault() == 0 && status[e].have_telemetry &&
              status[e].telemetry.fault() == 0 && status[e].telemetry.drives_enabled();
    }
    if (clear) return true;
    if (ground::Station::now_ns() >= deadline_ns) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

double DdsProvisioner::settle_time_sync(std::uint16_t mask, std::int64_t deadline_ns) const {
  const auto limit_ns = static_cast<std::int64_t>(config_.max_sync_round_trip_s * 1e9);
  for (;;) {
    std::int64_t worst = 0;
    for (int e = 0; e < ground::kEndcapCount; ++e) {
      if ((mask & (1U << e)) == 0) continue;
      const ground::EndcapStatus s = station_->snapshot()[e];
      worst = std::max(worst, s.seen && s.heartbeat.clock_synced() ? s.heartbeat.clock_round_trip_ns()
                                                                   : std::numeric_limits<std::int64_t>::max());
    }
    if (worst <= limit_ns || ground::Station::now_ns() >= deadline_ns) return static_cast<double>(worst) * 1e-9;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace tensegrity::hil

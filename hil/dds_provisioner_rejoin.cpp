// SPDX-License-Identifier: Apache-2.0
// DdsProvisioner during the run: a restarted end cap is brought back into the gait
// (real time: the supervisor thread sends it the run's start time; lockstep: its
// program starts on boot), unless the operator stopped the run with an emergency
// stop. The end cap's new life knows nothing of the stop its previous life took, so
// the launcher must not be the one that sets it moving beside eleven stopped end caps.
#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/fault.hpp"
#include "ground/command.hpp"
#include "hil/dds_provisioner.hpp"

namespace tensegrity::hil {

namespace {

constexpr auto kSupervisePeriod = std::chrono::milliseconds(20);
// Lockstep: an end cap started on boot is the launcher's to stop until its new life
// is heard on the link and at least this long after its spawn. An estop that
// reached the others before the spawn is heard within one heartbeat period (0.2 s)
// of it; one after that reaches the program through the operator's tool, which
// re-sends until every end cap on the link acks.
constexpr std::int64_t kRecallWindowNs = 500'000'000;

std::string left_idle(int endcap, int stopped_by) {
  return "dds: end cap " + std::to_string(endcap) + " back after a restart: left idle (end cap " +
         std::to_string(stopped_by) + " took an emergency stop; starting it again is the operator's: tensegrity start)";
}

std::string first_answer(const ground::CommandReport& r) {
  return r.results.empty() ? std::string("no answer") : r.results[0].text;
}

// For the line that settles a restart: how often the order was refused first, if at all.
std::string refusals_before(const RetryBackoff& retry, const char* order) {
  if (retry.refusals() == 0) return "";
  return " (after " + std::to_string(retry.refusals()) + " " + order +
         "(s) not accepted; last: " + retry.last_reason() + ")";
}

}  // namespace

int DdsProvisioner::operator_stop() const { return operator_stop(station_->snapshot()); }

// Heartbeats (5 Hz) carry the estop count; telemetry (100 Hz) shows the latched
// fault sooner, which matters to lockstep's one look when it spawns the program.
int DdsProvisioner::operator_stop(const std::array<ground::EndcapStatus, ground::kEndcapCount>& status) const {
  if (const int latched = operator_stop_.load(); latched >= 0) return latched;
  constexpr auto kEstop = static_cast<std::uint8_t>(core::FaultCause::emergency_stop);
  for (int e = 0; e < robot_.endcap_count(); ++e) {
    const ground::EndcapStatus& s = status[e];
    const bool estopped = (s.seen && (s.estops.count > 0 || s.heartbeat.fault() == kEstop)) ||
                          (s.have_telemetry && s.telemetry.fault() == kEstop);
    if (estopped) {
      int none = -1;
      operator_stop_.compare_exchange_strong(none, e);
      return operator_stop_.load();
    }
  }
  return -1;
}

void DdsProvisioner::on_restart(int endcap) {
  std::lock_guard lock(mutex_);
  if (endcap < 0 || endcap >= static_cast<int>(restarted_at_ns_.size())) return;
  if (config_.mode == StepperMode::lockstep && withheld_by_[endcap] >= 0) {
    log_.push_back(left_idle(endcap, withheld_by_[endcap]));
    return;
  }
  // Real time: to be started; lockstep: started on boot, watched by recall().
  restarted_at_ns_[endcap] = ground::Station::now_ns();
}

void DdsProvisioner::begin_run() {
  // Lockstep rejoins need no host (start on boot + the stepper's gate), but an
  // estop heard just after the spawn must still stop them: recall().
  if (supervisor_.joinable()) return;
  stopping_ = false;
  run_begun_ns_ = ground::Station::now_ns();
  unheard_since_ns_.assign(restarted_at_ns_.size(), 0);
  {
    std::lock_guard lock(mutex_);
    hearing_.assign(restarted_at_ns_.size(), HostHearing{});
  }
  supervisor_ = std::thread([this] {
    normal_priority();
    supervise();
  });
}

void DdsProvisioner::end_run() {
  stopping_ = true;
  if (!supervisor_.joinable()) return;
  supervisor_.join();
  run_ended_ns_ = ground::Station::now_ns();
  // A restart still pending that was refused: the run's log says so once, with the count.
  std::vector<int> refused;
  {
    std::lock_guard lock(mutex_);
    for (std::size_t e = 0; e < restarted_at_ns_.size(); ++e) {
      const RetryBackoff& r = retry_[e];
      if (restarted_at_ns_[e] != 0 && r.restart_ns() == restarted_at_ns_[e] && r.refusals() > 0)
        refused.push_back(static_cast<int>(e));
    }
  }
  for (const int e : refused) {
    const RetryBackoff& r = retry_[static_cast<std::size_t>(e)];
    const bool realtime = config_.mode == StepperMode::realtime;
    note("dds: end cap " + std::to_string(e) + " back after a restart: " +
         (realtime ? "not started by the run's end; its start" : "not stopped by the run's end; its stop") +
         " was not accepted " + std::to_string(r.refusals()) + " time(s) (last: " + r.last_reason() + ")");
  }
}

void DdsProvisioner::settle_restart(int endcap, std::int64_t since, const std::string& line) {
  std::lock_guard lock(mutex_);
  if (restarted_at_ns_[endcap] == since) restarted_at_ns_[endcap] = 0;
  if (!line.empty()) log_.push_back(line);
}

// Real time: a restarted end cap is idle with its stored table. Once it is back on
// the link, synchronized and with its drives enabled, it gets the run's original
// start time: it plays its table as far along as the others, in phase.
void DdsProvisioner::supervise() {
  while (!stopping_) {
    std::this_thread::sleep_for(kSupervisePeriod);
    const auto status = station_->snapshot();
    if (config_.mode == StepperMode::realtime) watch_link(status, ground::Station::now_ns());
    operator_stop(status);  // latched when it happens, restart or not
    std::vector<std::pair<int, std::int64_t>> pending;
    {
      std::lock_guard lock(mutex_);
      for (std::size_t e = 0; e < restarted_at_ns_.size(); ++e) {
        if (restarted_at_ns_[e] != 0) pending.emplace_back(static_cast<int>(e), restarted_at_ns_[e]);
      }
    }
    for (const auto& [e, since] : pending) {
      retry_[static_cast<std::size_t>(e)].follow(since);
      if (config_.mode == StepperMode::realtime) {
        rejoin(e, since, status[e]);
      } else {
        recall(e, since, status[e]);
      }
    }
  }
}

// Lockstep decided at the spawn that the program starts on boot. An estop the
// launcher hears in the recall window (kRecallWindowNs) may have reached the others
// before the spawn, and the operator's tool may be done before the new program is on
// the link: the launcher stops it (idle, as if it had been left idle), re-sending
// until it acks. After the window it is the operator's, as any playing end cap is.
void DdsProvisioner::recall(int e, std::int64_t since, const ground::EndcapStatus& s) {
  const int stopped_by = operator_stop();
  if (stopped_by < 0) {
    const bool heard = s.seen && s.heartbeat_host_ns > since;
    if (heard && ground::Station::now_ns() - since > kRecallWindowNs) settle_restart(e, since, "");
    return;
  }
  ground::CommandOptions co;
  co.endcap_mask = static_cast<std::uint16_t>(1U << e);
  co.timeout_s = config_.command_timeout_s;
  const ground::CommandReport r = ground::send_command(*station_, ground::CommandKind::stop, 0, co);
  // Never gated by retry.due(): a stop must not wait (the others are already stopped);
  // the backoff only thins its log lines.
  RetryBackoff& retry = retry_[static_cast<std::size_t>(e)];
  if (r.all_accepted()) {
    settle_restart(e, since,
                   "dds: end cap " + std::to_string(e) +
                       " back after a restart: stopped (it started on boot as end cap " + std::to_string(stopped_by) +
                       " took an emergency stop; starting it again is the operator's: tensegrity start)" +
                       refusals_before(retry, "stop"));
  } else if (retry.refused(ground::Station::now_ns(), first_answer(r))) {
    note("dds: end cap " + std::to_string(e) + " back after a restart: stop not accepted (" + retry.last_reason() +
         "; " + std::to_string(retry.refusals()) + " time(s) so far); trying again");
  }
}

void DdsProvisioner::rejoin(int e, std::int64_t since, const ground::EndcapStatus& s) {
  RetryBackoff& retry = retry_[static_cast<std::size_t>(e)];
  if (s.have_telemetry && s.telemetry_host_ns > since && s.telemetry.mode() == 1) {
    // Its commands reader is volatile, so only a start sent after it came back
    // (an operator's `tensegrity start`) can have set it playing. Nothing left to do.
    settle_restart(e, since,
                   "dds: end cap " + std::to_string(e) + " back after a restart: already playing" +
                       refusals_before(retry, "start"));
    return;
  }
  // Checked at every step: an estop may land while the end cap is coming back.
  if (const int stopped_by = operator_stop(); stopped_by >= 0) {
    settle_restart(e, since, left_idle(e, stopped_by) + refusals_before(retry, "start"));
    return;
  }
  // The clear names the estops this life took: wait for its own heartbeat.
  if (s.have_telemetry && s.telemetry_host_ns > since && s.telemetry.fault() != 0 && s.heartbeat_host_ns > since) {
    // Latched while coming back (a sample late while the emulator served the
    // others): the same clear-fault as before the run's start. Tried once: an
    // end cap it does not clear (an operator's estop) is left as it is.
    if (!clear_faults_before_start(static_cast<std::uint16_t>(1U << e),
                                   ground::Station::now_ns() + core::seconds_to_ns(config_.command_timeout_s))) {
      // clear_faults_before_start said why; only the starts not accepted before are left to say.
      const std::string before = refusals_before(retry, "start");
      settle_restart(e, since, before.empty() ? "" : "dds: end cap " + std::to_string(e) + " left faulted" + before);
    }
    return;
  }
  const bool ready = s.seen && s.heartbeat_host_ns > since && s.heartbeat.clock_synced() && s.have_telemetry &&
                     s.telemetry_host_ns > since && s.telemetry.drives_enabled() && s.telemetry.mode() == 0 &&
                     s.telemetry.fault() == 0;
  if (!ready || !retry.due(ground::Station::now_ns())) return;
  // Its phase is as good as its clock: give the time sync a moment.
  const double round_trip_s =
      settle_time_sync(static_cast<std::uint16_t>(1U << e),
                       ground::Station::now_ns() + core::seconds_to_ns(config_.rejoin_sync_settle_timeout_s));
  // The last look before it moves: an estop in the settling time still wins.
  if (const int stopped_by = operator_stop(); stopped_by >= 0) {
    settle_restart(e, since, left_idle(e, stopped_by) + refusals_before(retry, "start"));
    return;
  }
  ground::CommandOptions co;
  co.endcap_mask = static_cast<std::uint16_t>(1U << e);
  co.timeout_s = config_.command_timeout_s;
  const ground::CommandReport r = ground::send_command(*station_, ground::CommandKind::start, start_host_ns_, co);
  char line[300];
  const double behind_s = static_cast<double>(ground::Station::now_ns() - start_host_ns_) * 1e-9;
  if (r.all_accepted()) {
    std::snprintf(line, sizeof line,
                  "dds: end cap %d back after a restart: started at the run's start time (table %.3f s along; "
                  "time-sync round trip %.3f ms)",
                  e, behind_s, round_trip_s * 1e3);
    settle_restart(e, since, line + refusals_before(retry, "start"));
  } else if (retry.refused(ground::Station::now_ns(), first_answer(r))) {
    std::snprintf(line, sizeof line,
                  "dds: end cap %d back after a restart: start not accepted (%s; %d time(s) so far); trying again "
                  "in %.2f s",
                  e, retry.last_reason().c_str(), retry.refusals(), static_cast<double>(retry.wait_ns()) * 1e-9);
    note(line);
  }
}

}  // namespace tensegrity::hil

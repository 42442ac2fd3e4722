// SPDX-License-Identifier: Apache-2.0
#include "hil/endcap_roster.hpp"

#include <sstream>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {
constexpr std::int64_t kRestartPollNs = 200'000;

double ns_to_s(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }
}  // namespace

EndcapRoster::EndcapRoster(const sim::Robot& robot, const fw::SpoolGeometry& spool, bool lockstep,
                           EndcapProcesses& processes)
    : processes_(processes) {
  endcaps_.reserve(static_cast<std::size_t>(robot.endcap_count()));
  for (int e = 0; e < robot.endcap_count(); ++e) {
    endcaps_.push_back({EndcapDevices(e, robot.cables_of(e), spool, robot.motor.max_rest_length_m, lockstep)});
  }
}

bool EndcapRoster::admit(int e) {
  Endcap& ec = endcaps_[e];
  if (ec.state == EndcapState::waiting_process && processes_.listening(e)) {
    ec.state = EndcapState::live;
    ec.first_answer_pending = true;
  }
  return ec.state == EndcapState::live;
}

void EndcapRoster::admit_listening(std::int64_t now_ns) {
  bool waiting = false;
  for (const Endcap& ec : endcaps_) waiting = waiting || ec.state == EndcapState::waiting_process;
  if (!waiting || !admit_check_.due(now_ns)) return;
  for (int e = 0; e < size(); ++e) admit(e);
}

// Without this a program that fails at start (a bad config, a missing library) would
// cost the whole boot timeout and then be reported among the slow ones.
void EndcapRoster::fail_on_exit(std::int64_t now_ns) {
  if (!exit_check_.due(now_ns)) return;
  for (int e = 0; e < size(); ++e) {
    if (!processes_.exited(e)) continue;
    throw HilError("boot: end cap " + std::to_string(e) +
                   "'s program exited before the start gate: " + processes_.describe(e));
  }
}

// Lockstep owns time: nothing moves while an end cap's program starts again, as
// nothing moves while one is slow to answer. The physics time the end cap misses is
// then the scenario's (from its kill to its restart, plus its bring-up in SYNC ticks),
// not however long the host takes to start a process, and a run with restarts is as
// reproducible as one without.
void EndcapRoster::await_restarted(Clock& clock, const std::stop_token& stop, std::int64_t timeout_ns,
                                   std::int64_t step) {
  const std::int64_t t0 = clock.now_ns();
  for (;;) {
    std::string waiting;
    for (int e = 0; e < size(); ++e) {
      if (endcaps_[e].state != EndcapState::waiting_process || admit(e)) continue;
      waiting += " end cap " + std::to_string(e) + " (" + processes_.describe(e) + ");";
    }
    if (waiting.empty()) return;
    if (stop.stop_requested()) throw HilError("interrupted");
    for (int e = 0; e < size(); ++e) {
      if (endcaps_[e].state != EndcapState::waiting_process || !processes_.exited(e)) continue;
      throw HilError("lockstep: end cap " + std::to_string(e) +
                     "'s restarted program exited before it listened on its bus (physics step " + std::to_string(step) +
                     "): " + processes_.describe(e));
    }
    if (clock.now_ns() - t0 > timeout_ns) {
      std::ostringstream why;
      why << "lockstep: a restarted program is not listening on its bus within " << ns_to_s(timeout_ns)
          << " s (physics step " << step << "):" << waiting;
      throw HilError(why.str());
    }
    clock.sleep_until(clock.now_ns() + kRestartPollNs, 0);
  }
}

void EndcapRoster::kill(int e) {
  processes_.kill(e);
  endcaps_[e].state = EndcapState::down;
  endcaps_[e].devices.on_connection_lost();
}

void EndcapRoster::restart(int e) {
  Endcap& ec = endcaps_[e];
  if (ec.state == EndcapState::live) processes_.kill(e);
  ec.devices.on_connection_lost();
  processes_.restart(e);
  ec.state = EndcapState::waiting_process;
  ec.first_answer_pending = true;
  ec.awaited = true;  // a new program
}

std::string EndcapRoster::freeze(int e, bool loop_only) {
  std::string why = processes_.freeze(e, loop_only);
  if (why.empty()) endcaps_[e].awaited = false;
  return why;
}

bool EndcapRoster::all_at_gate() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.state != EndcapState::live || !ec.devices.at_gate()) return false;
  }
  return true;
}

bool EndcapRoster::any_to_tick() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.state == EndcapState::live && !ec.devices.at_gate()) return true;
  }
  return false;
}

bool EndcapRoster::release_arrived() {
  bool all_enabled = true;
  for (Endcap& ec : endcaps_) {
    if (ec.state == EndcapState::live && ec.devices.at_gate()) ec.devices.release_gate();
    all_enabled = all_enabled && ec.state == EndcapState::live && ec.devices.any_follows();
  }
  return all_enabled;
}

std::string EndcapRoster::boot_report(std::int64_t timeout_ns) {
  std::ostringstream s;
  s << "boot: not every end cap reached the start gate (drives switched on, asking for operation enabled) within "
    << ns_to_s(timeout_ns) << " s:";
  for (int e = 0; e < size(); ++e) {
    const Endcap& ec = endcaps_[e];
    if (ec.state == EndcapState::live && ec.devices.at_gate()) continue;
    s << " end cap " << e << " ";
    if (ec.state != EndcapState::live) {
      s << "has no bus socket";
    } else {
      for (std::size_t m = 0; m < ec.devices.motor_count(); ++m) {
        s << (m ? ", " : "") << "drive node " << static_cast<int>(ec.devices.drive_node(m)) << " "
          << to_string(ec.devices.drive(m).state());
      }
    }
    s << " (" << processes_.describe(e) << ");";
  }
  return s.str();
}

bool EndcapRoster::any_expected() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.expected) return true;
  }
  return false;
}

bool EndcapRoster::first_answer_expected() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.expected && ec.first_answer_pending) return true;
  }
  return false;
}

bool EndcapRoster::all_answered() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.expected && !ec.devices.all_rpdos()) return false;
  }
  return true;
}

std::string EndcapRoster::missing_answers() {
  std::string why;
  for (int e = 0; e < size(); ++e) {
    const Endcap& ec = endcaps_[e];
    if (!ec.expected || ec.devices.all_rpdos()) continue;
    why += " end cap " + std::to_string(e) + " sent no RPDO1 for drive node(s) " + ec.devices.missing_rpdo_nodes() +
           " (" + processes_.describe(e) + ");";
  }
  return why;
}

void EndcapRoster::answered() {
  for (Endcap& ec : endcaps_) {
    if (ec.expected) ec.first_answer_pending = false;
  }
}

}  // namespace tensegrity::hil

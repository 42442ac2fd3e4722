// SPDX-License-Identifier: Apache-2.0
// The roster of a HIL run's end caps: each one's emulated devices, whether its
// program is there to talk to (state), its start gate, and the supervision of its
// process (admitted when its bus socket exists, failed when it exits where it
// must not). The world stepper asks it who gets a tick and who must answer it.
#pragma once

#include <cstdint>
#include <stop_token>
#include <string>
#include <vector>

#include "firmware/drivers/spool_geometry.hpp"
#include "hil/clock.hpp"
#include "hil/endcap_devices.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {

// What the roster needs from whoever runs the end-cap programs.
class EndcapProcesses {
 public:
  virtual ~EndcapProcesses() = default;
  // Its bus socket exists: frames sent to it now queue until it reads them.
  virtual bool listening(int endcap) = 0;
  // Its program was started and has ended since: it will not answer until restarted.
  virtual bool exited(int endcap) = 0;
  // For error messages: "pid 1234, running", "exited with status 2".
  virtual std::string describe(int endcap) = 0;
  virtual void kill(int endcap) = 0;
  virtual void restart(int endcap) = 0;
  // Cuts (up = false) or restores the end cap's DDS link to the host. Returns why
  // it was not done ("" when done): no DDS link in this run, not running, ...
  virtual std::string set_dds_link(int endcap, bool up) = 0;
  // Its DDS participant of the moment stops sending and still hears (a handshake
  // stalled one way; the end cap's rejoin clears it). Returns why not ("" when done).
  virtual std::string mute_dds(int endcap) {
    (void)endcap;
    return "not supported by this launcher";
  }
  // Fault injection: SIGSTOP the program (a dead end cap, nothing of it runs), or
  // with loop_only hang its control loop alone (the test hook --hang-loop-signal).
  // Returns why it was not done ("" when done).
  virtual std::string freeze(int endcap, bool loop_only) {
    (void)endcap;
    (void)loop_only;
    return "not supported by this launcher";
  }
};

enum class EndcapState : std::uint8_t {
  waiting_process,  // no socket yet (starting, or killed and not restarted)
  live,             // answers every SYNC
  down,             // killed by the scenario
};

// At most one check per period: reading /proc for twelve processes every tick
// would cost more than the tick.
class RateLimit {
 public:
  explicit RateLimit(std::int64_t period_ns) : period_ns_(period_ns) {}
  bool due(std::int64_t now_ns) {
    if (checked_ && now_ns - last_ns_ < period_ns_) return false;
    checked_ = true;
    last_ns_ = now_ns;
    return true;
  }

 private:
  std::int64_t period_ns_;
  std::int64_t last_ns_ = 0;
  bool checked_ = false;
};

class EndcapRoster {
 public:
  static constexpr std::int64_t kCheckPeriodNs = 1'000'000;

  EndcapRoster(const sim::Robot& robot, const fw::SpoolGeometry& spool, bool lockstep, EndcapProcesses& processes);

  int size() const { return static_cast<int>(endcaps_.size()); }
  EndcapState state(int endcap) const { return endcaps_[endcap].state; }
  bool live(int endcap) const { return endcaps_[endcap].state == EndcapState::live; }
  EndcapDevices& devices(int endcap) { return endcaps_[endcap].devices; }
  const EndcapDevices& devices(int endcap) const { return endcaps_[endcap].devices; }
  EndcapProcesses& processes() { return processes_; }

  // --- supervision ---
  // Programs whose bus socket now exists become live (checked at most once per
  // kCheckPeriodNs, and only while one is waiting).
  void admit_listening(std::int64_t now_ns);
  // Boot: throws HilError naming an end cap whose program exited (rate-limited
  // like admit_listening): it will never reach the gate.
  void fail_on_exit(std::int64_t now_ns);
  // Lockstep run: waits until every restarted program listens; nothing moves
  // meanwhile. Throws HilError if one exits first, on a stop, or after timeout_ns.
  void await_restarted(Clock& clock, const std::stop_token& stop, std::int64_t timeout_ns, std::int64_t step);
  // The scenario's kill and restart (the bus side is the caller's).
  void kill(int endcap);
  void restart(int endcap);
  // stop_endcap, hang_loop: its bus and devices keep running, the barrier no
  // longer waits for it. Returns why not ("" when done).
  std::string freeze(int endcap, bool loop_only);
  bool awaited(int endcap) const { return endcaps_[endcap].awaited; }

  // --- the start gate ---
  bool all_at_gate() const;
  bool any_to_tick() const;  // live and not waiting at the gate
  // Real time, gate on arrival: opens every gate reached; whether every end cap
  // is live with a drive enabled.
  bool release_arrived();
  std::string boot_report(std::int64_t timeout_ns);

  // --- one lockstep tick's answers ---
  void expect(int endcap, bool expected) { endcaps_[endcap].expected = expected; }
  bool any_expected() const;
  bool first_answer_expected() const;  // from a program just (re)started: it may be slow
  bool all_answered() const;
  std::string missing_answers();  // " end cap 9 sent no RPDO1 for drive node(s) 1, 3 (pid ...);"
  void answered();

 private:
  struct Endcap {
    EndcapDevices devices;
    EndcapState state = EndcapState::waiting_process;
    bool first_answer_pending = true;
    bool expected = false;  // a SYNC went out this tick: wait for its RPDO1s
    // False once the scenario froze it (stop_endcap, hang_loop).
    bool awaited = true;
  };
  // Admits end cap `e` if its program listens; returns whether it is live.
  bool admit(int e);

  std::vector<Endcap> endcaps_;
  EndcapProcesses& processes_;
  RateLimit admit_check_{kCheckPeriodNs};
  RateLimit exit_check_{kCheckPeriodNs};
};

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
// The world stepper: owns time, the robot model and, on every end cap's bus, that
// end cap's devices (EndcapDevices). One object, one thread.
//
// Lockstep, one control tick k (= physics step k once started):
//   1. scenario events due at k * dt are applied (device faults, frame faults,
//      process kill/restart);
//   2. on every live bus: heartbeats due, the sensor PDOs (drive status/position
//      from the model's rest length through the spool, load-cell tensions) and
//      then SYNC, all in one batched send;
//   3. barrier: wait for RPDO1 from every drive of every live end cap (SDO and
//      NMT traffic on the way is answered at once, so the answers are queued
//      before the next SYNC); a timeout names the end cap and drive node(s);
//   4. preferred rest lengths from the drives' targets (a drive that is not
//      operation-enabled, or is faulted, holds its cable) and one physics step.
// So the end cap's cycle k sees the sensors after physics step k-1 and its
// targets drive physics step k: what sim::CoreController does in process.
//
// Boot: SYNCs flow with physics frozen at the start state. Each drive's enable is
// gated (SimCia402Drive::hold_enable): an end cap whose drives all wait at the
// gate gets no more SYNCs (its time stands still, so its bring-up timeout does
// not run) until every end cap waits there; then all gates open in the same tick,
// which is physics step 0 and table time 0 on every end cap (start on boot starts
// the table in the cycle that sees the drives enabled). An end cap that comes back
// later (restart, fault reset) waits at the gate until a multiple of the policy
// period, so it rejoins in phase. While a restarted program starts (no bus socket
// yet) no tick happens at all: a restart costs the same physics time on any host.
//
// Real time: the end caps run their own 1 kHz timers and send SYNC; the devices
// answer SYNC; the stepper paces physics to the wall clock and counts late steps.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/drivers/spool_geometry.hpp"
#include "hil/answer_nap.hpp"
#include "hil/endcap_devices.hpp"
#include "hil/lateness.hpp"
#include "hil/recorder.hpp"
#include "hil/scenario.hpp"
#include "hil/start_handshake.hpp"
#include "hil/udp_hub.hpp"
#include "sim/model.hpp"

namespace tensegrity::hil {

// What the stepper needs from whoever runs the end-cap programs.
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
  // Fault injection: SIGSTOP the program (a dead end cap, nothing of it runs), or
  // with loop_only hang its control loop alone (the test hook --hang-loop-signal).
  // Returns why it was not done ("" when done).
  virtual std::string freeze(int endcap, bool loop_only) {
    (void)endcap;
    (void)loop_only;
    return "not supported by this launcher";
  }
};

enum class StepperMode : std::uint8_t { lockstep, realtime };
const char* to_string(StepperMode mode);

struct StepperConfig {
  StepperMode mode = StepperMode::lockstep;
  std::int64_t barrier_timeout_ns = 2'000'000'000;
  // A process just started (or restarted) may take longer for its first answer.
  std::int64_t first_answer_timeout_ns = 10'000'000'000;
  std::int64_t boot_timeout_ns = 30'000'000'000;
  fw::SpoolGeometry spool;
  // Rejoin gate: table time 0 only at multiples of this many steps (the policy
  // period), so a restarted end cap plays in phase. 0: release at once.
  std::int64_t phase_period_steps = 0;
  // Real time, for a provisioner that starts the tables itself (DDS start at a
  // host time): each end cap's drives are enabled as soon as they ask, and boot
  // ends when all are. A common gate is then not needed, and in real time it
  // cannot hold: an end cap waiting at it retries its bring-up after 2 s of its
  // own clock, so twelve end caps whose programs start seconds apart on a loaded
  // host (each creating its DDS participant first) never all wait there at once.
  bool realtime_gate_on_arrival = false;
  // Real time: the stepper sleeps to this long before each step's deadline and
  // polls the clock from there (pacer.hpp).
  std::int64_t spin_ns = 50'000;
  // Lockstep: sleep this fraction of the end caps' usual answer time before
  // waiting on the socket (answer_nap.hpp); 0: wait on the socket at once.
  double answer_nap_fraction = 0.7;
};

enum class EndcapState : std::uint8_t {
  waiting_process,  // no socket yet (starting, or killed and not restarted)
  live,             // answers every SYNC
  down,             // killed by the scenario
};

struct StepperStats {
  std::int64_t boot_ticks = 0;
  std::int64_t steps = 0;  // physics steps
  double boot_wall_s = 0.0;
  double run_wall_s = 0.0;
  std::int64_t late_steps = 0;     // realtime: began > half a period after its deadline (lateness.hpp)
  double max_lateness_s = 0.0;
  LatenessSummary lateness;        // realtime: the whole distribution
  double max_barrier_wait_s = 0.0;  // lockstep: longest wait for the end caps' answers
  std::int64_t rejoins = 0;        // gates opened after the start (restart, reset)
  double max_tension_n = 0.0;
  // Lockstep wall-time breakdown of the run phase: sending (sensor PDOs + SYNC),
  // waiting for and serving the end caps' answers, the physics step.
  double send_wall_s = 0.0, barrier_wall_s = 0.0, physics_wall_s = 0.0;
  // Between the start gate and physics step 0 while a provisioner works (hold()).
  std::int64_t hold_ticks = 0;
  double hold_wall_s = 0.0;
  double sim_time_s() const;
  double dt_s = 0.001;
};

class WorldStepper {
 public:
  WorldStepper(const sim::Robot& robot, const sim::ModelState& start, UdpHub& hub, EndcapProcesses& processes,
               const StepperConfig& config);

  void set_scenario(const Scenario& scenario) { scenario_ = scenario; }
  void set_recorder(Recorder* recorder) { recorder_ = recorder; }
  // Called after each physics step (tests, progress).
  void set_step_hook(std::function<void(const WorldStepper&)> hook) { hook_ = std::move(hook); }

  // Until every end cap waits at the start gate. Throws HilError naming the end
  // caps that did not make it.
  void boot();
  // Opens every gate: the next tick is physics step 0 and table time 0.
  void start();
  // After start(), for a provisioner that talks to the running end caps (DDS):
  // their buses are served and, in lockstep, SYNCs flow at the wall clock's pace,
  // physics frozen, until the handshake names physics step 0 (start_handshake.hpp).
  // Throws HilError on the handshake's failure, an interrupt or `timeout_ns`.
  void hold(StartHandshake& handshake, std::int64_t timeout_ns);
  // Real time, after run(): keeps serving the end caps' buses (physics frozen)
  // until `done()` or `timeout_ns`, so end caps being shut down do not trip their
  // sensor and drive timeouts in the milliseconds before they exit (their state
  // at exit is the run's result). Lockstep needs none: without SYNC no time passes.
  void serve_until(const std::function<bool()>& done, std::int64_t timeout_ns);
  // Physics for duration_s after start(). Throws HilError on a stuck end cap.
  void run(double duration_s);

  const sim::Model& model() const { return *model_; }
  double distance_m() const;
  const StepperStats& stats() const { return stats_; }
  EndcapState state(int endcap) const { return endcaps_[endcap].state; }
  const EndcapDevices& devices(int endcap) const { return endcaps_[endcap].devices; }
  EndcapDevices& devices(int endcap) { return endcaps_[endcap].devices; }
  int endcap_count() const { return static_cast<int>(endcaps_.size()); }
  // What happened, one line each (scenario events applied, rejoins, skipped).
  const std::vector<std::string>& log() const { return log_; }
  std::int64_t step_index() const { return stats_.steps; }

 private:
  struct Endcap {
    EndcapDevices devices;
    EndcapState state = EndcapState::waiting_process;
    bool first_answer_pending = true;
    bool expected = false;  // a SYNC went out this tick: wait for its RPDO1s
    // False once the scenario froze it (stop_endcap, hang_loop): its bus and devices
    // keep running, the barrier no longer waits for it.
    bool awaited = true;
  };

  std::int64_t now_device_ns() const { return ticks_ * period_ns_; }
  void admit_listening();
  void await_restarted();  // lockstep run: hold time until restarted programs listen
  void fail_on_exit();     // boot: an end cap whose program ended will never reach the gate
  void lockstep_tick(bool physics);
  void barrier(std::int64_t tick);
  void route(const std::vector<UdpHub::Rx>& rx);  // serve() and send the answers
  void serve(const std::vector<UdpHub::Rx>& rx);  // frames to the devices, answers queued
  void physics_step();
  void apply_due_events();
  void apply(const ScenarioEvent& event);
  void update_frame_faults();
  bool all_at_gate() const;
  std::string boot_report() const;
  void run_realtime(double duration_s);
  void boot_realtime();
  void hold_lockstep(StartHandshake& handshake, std::int64_t deadline_ns);
  void hold_realtime(StartHandshake& handshake, std::int64_t deadline_ns);
  void serve_frames_until(std::int64_t until_ns);
  void idle_realtime_tick();
  void apply_dds_link(const ScenarioEvent& event);
  void note(const std::string& line);

  const sim::Robot& robot_;
  std::unique_ptr<sim::Model> model_;
  UdpHub& hub_;
  EndcapProcesses& processes_;
  StepperConfig config_;
  AnswerNap nap_{config_.answer_nap_fraction};
  std::int64_t period_ns_;
  std::vector<Endcap> endcaps_;
  Scenario scenario_;
  std::size_t next_event_ = 0;
  struct FrameFault {
    int endcap;
    bool corrupt;
    std::int64_t until_step;  // -1: to the end
  };
  std::vector<FrameFault> frame_faults_;
  Recorder* recorder_ = nullptr;
  std::function<void(const WorldStepper&)> hook_;
  std::vector<double> preferred_;
  Eigen::Vector3d start_centre_;
  std::int64_t ticks_ = 0;  // device time in ticks, boot included
  std::int64_t last_exit_check_ns_ = 0;
  bool started_ = false;
  StepperStats stats_;
  std::vector<std::string> log_;
  FrameOut out_;
  std::vector<UdpHub::Rx> rx_;
};

}  // namespace tensegrity::hil

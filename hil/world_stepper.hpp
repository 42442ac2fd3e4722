// SPDX-License-Identifier: Apache-2.0
// The world stepper: owns the robot model and orchestrates one HIL run's time.
// It holds the parts that do the work, each with one job:
//   - TickSource (tick_source.hpp): where ticks come from, on a given clock:
//     the lockstep barrier, real-time pacing and late-step counting;
//   - EndcapRoster (endcap_roster.hpp): the end caps' devices, state, start gates
//     and the supervision of their programs;
//   - FaultInjector (fault_injector.hpp): scenario events -> device actions;
// and the hub (udp_hub.hpp) that carries every bus.
//
// Lockstep, one control tick k (= physics step k once started):
//   1. scenario events due at k * dt are applied;
//   2. on every live bus: heartbeats due, the sensor PDOs (drive status/position
//      from the model's rest length through the spool, load-cell tensions) and
//      then SYNC, all in one batched send;
//   3. barrier: wait for RPDO1 from every drive of every live end cap (SDO and
//      NMT traffic on the way is answered at once); a timeout names the end cap
//      and drive node(s);
//   4. preferred rest lengths from the drives' targets (a drive that is not
//      operation-enabled, or is faulted, holds its cable) and one physics step.
// So the end cap's cycle k sees the sensors after physics step k-1 and its
// targets drive physics step k: what sim::CoreController does in process.
//
// Boot: SYNCs flow with physics frozen at the start state. Each drive's enable is
// gated (SimCia402Drive::hold_enable): an end cap whose drives all wait at the
// gate gets no more SYNCs (its time stands still, so its bring-up timeout does
// not run) until every end cap waits there; then all gates open in the same tick,
// which is physics step 0 and table time 0 on every end cap. An end cap that comes
// back later (restart, fault reset) waits at the gate until a multiple of the
// policy period, so it rejoins in phase. While a restarted program starts (no bus
// socket yet) no tick happens at all: a restart costs the same physics time on
// any host.
//
// Real time: the end caps run their own 1 kHz timers and send SYNC; the devices
// answer SYNC; the stepper paces physics to the wall clock and counts late steps.
//
// A stop requested on the std::stop_token ends any phase with HilError("interrupted").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stop_token>
#include <string>
#include <vector>

#include "firmware/drivers/spool_geometry.hpp"
#include "hil/clock.hpp"
#include "hil/endcap_roster.hpp"
#include "hil/fault_injector.hpp"
#include "hil/lateness.hpp"
#include "hil/recorder.hpp"
#include "hil/scenario.hpp"
#include "hil/start_handshake.hpp"
#include "hil/tick_source.hpp"
#include "hil/udp_hub.hpp"
#include "robot/start_frame.hpp"
#include "sim/model/model.hpp"

namespace tensegrity::hil {

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
  // Lockstep: physics at most this many times real time (0: as fast as the end
  // caps answer), like Gazebo's real-time factor or PX4's speed factor.
  double max_speed = 0.0;
};

struct StepperStats {
  std::int64_t boot_ticks = 0;
  std::int64_t steps = 0;  // physics steps
  double boot_wall_s = 0.0;
  double run_wall_s = 0.0;
  std::int64_t late_steps = 0;  // realtime: began > half a period after its deadline (lateness.hpp)
  double max_lateness_s = 0.0;
  LatenessSummary lateness;         // realtime: the whole distribution
  double max_barrier_wait_s = 0.0;  // lockstep: longest wait for the end caps' answers
  std::int64_t rejoins = 0;         // gates opened after the start (restart, reset)
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

// The start frame of the model's pose now (sim/start_frame.hpp), and the face it stands on.
sim::StartFrame frame_now(const sim::Model& model, const std::vector<sim::HullFace>& faces, std::vector<int>& face);

class WorldStepper final : private TickAnswers {
 public:
  // `clock` and `stop` are the run's; the clock must outlive the stepper.
  WorldStepper(const sim::Robot& robot, const sim::ModelState& start, UdpHub& hub, EndcapProcesses& processes,
               const StepperConfig& config, Clock& clock, std::stop_token stop = {});

  void set_scenario(const Scenario& scenario) { faults_ = FaultInjector(scenario, stats_.dt_s); }
  void set_recorder(Recorder* recorder) { recorder_ = recorder; }
  void set_operator(OperatorCommand command) { fault_target_.set_operator(std::move(command)); }
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
  // Throws HilError on the handshake's failure, a stop or `timeout_ns`.
  void hold(StartHandshake& handshake, std::int64_t timeout_ns);
  // Real time, after run(): keeps serving the end caps' buses (physics frozen)
  // until `done()` or `timeout_ns`, so end caps being shut down do not trip their
  // sensor and drive timeouts in the milliseconds before they exit (their state
  // at exit is the run's result). Lockstep needs none: without SYNC no time passes.
  void serve_until(const std::function<bool()>& done, std::int64_t timeout_ns);
  // Physics for duration_s after start(). Throws HilError on a stuck end cap.
  void run(double duration_s);

  const sim::Model& model() const { return *model_; }
  // Where the robot went since physics step 0, in the world and its start frame.
  sim::Travel travel() const;
  // The end caps of the hull face the robot stood on at physics step 0.
  const std::vector<int>& start_face() const { return start_face_; }
  const StepperStats& stats() const { return stats_; }
  EndcapState state(int endcap) const { return roster_.state(endcap); }
  const EndcapDevices& devices(int endcap) const { return roster_.devices(endcap); }
  EndcapDevices& devices(int endcap) { return roster_.devices(endcap); }
  int endcap_count() const { return roster_.size(); }
  // What happened, one line each (scenario events applied, rejoins, skipped).
  const std::vector<std::string>& log() const { return log_; }
  std::int64_t step_index() const { return stats_.steps; }

 private:
  // TickAnswers, for the lockstep barrier.
  bool all_in() const override { return roster_.all_answered(); }
  bool receive(std::int64_t deadline_ns) override;
  void forget_arrivals() override { hub_.reset_latest_arrival(); }
  std::int64_t latest_arrival_ns() const override { return hub_.latest_arrival_ns(); }
  std::string missing() override { return roster_.missing_answers(); }

  std::int64_t now_device_ns() const { return ticks_ * source_.period_ns(); }
  bool pass_gate(int endcap);  // lockstep: a gate after the start opens on a period boundary
  void lockstep_tick(bool physics);
  void send_tick(int endcap, bool sync);          // due frames (+ sensors and SYNC) to one live end cap
  void serve(const std::vector<UdpHub::Rx>& rx);  // frames to the devices, answers queued
  void physics_step();
  void apply_faults();
  void boot_lockstep();
  void boot_realtime();
  void run_lockstep(std::int64_t steps);
  void run_realtime(std::int64_t steps);
  void hold_lockstep(StartHandshake& handshake, std::int64_t deadline_ns);
  void freeze_and_start(StartHandshake& handshake, std::int64_t deadline_ns, const FrozenTick& last);
  void hold_realtime(StartHandshake& handshake, std::int64_t deadline_ns);
  void serve_frames_until(std::int64_t until_ns);
  void idle_realtime_tick();
  void note(const std::string& line);

  std::unique_ptr<sim::Model> model_;
  UdpHub& hub_;
  StepperConfig config_;
  TickSource source_;
  EndcapRoster roster_;
  FaultInjector faults_;
  LiveFaultTarget fault_target_;
  Recorder* recorder_ = nullptr;
  std::function<void(const WorldStepper&)> hook_;
  std::vector<double> preferred_;
  std::vector<sim::HullFace> faces_;
  sim::StartFrame start_frame_;
  std::vector<int> start_face_;
  std::int64_t ticks_ = 0;  // device time in ticks, boot included
  bool started_ = false;
  StepperStats stats_;
  std::vector<std::string> log_;
  FrameOut out_;
  std::vector<UdpHub::Rx> rx_;
};

}  // namespace tensegrity::hil

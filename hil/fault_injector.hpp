// SPDX-License-Identifier: Apache-2.0
// The scenario's faults (scenario.hpp), applied when physics time reaches them:
// each event becomes actions on an end cap's devices, its bus or its program,
// through a FaultTarget, so the mapping is tested without processes or sockets.
// Frame faults with a duration are ended when it is over.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hil/endcap_devices.hpp"
#include "hil/scenario.hpp"
#include "hil/udp_hub.hpp"

namespace tensegrity::hil {

class EndcapRoster;

// What a fault acts on.
class FaultTarget {
 public:
  virtual ~FaultTarget() = default;
  virtual int endcap_count() const = 0;
  virtual EndcapDevices& devices(int endcap) = 0;
  // Frames for the end cap's bus ahead of this tick's own (a drive's EMCY).
  virtual void send(int endcap, const FrameOut& frames) = 0;
  virtual void set_drop(int endcap, double probability) = 0;
  virtual void set_corrupt(int endcap, double probability, CorruptKind kind) = 0;
  virtual void kill(int endcap) = 0;
  virtual void restart(int endcap) = 0;
  // "" when done, else why not (no DDS link in this run, not running, ...).
  virtual std::string set_dds_link(int endcap, bool up) = 0;
  // Its DDS participant of the moment stops sending (mute_dds). "" when done, else why not.
  virtual std::string mute_dds(int endcap) = 0;
  // SIGSTOP the program (loop_only: hang its control loop alone); the barrier no
  // longer waits for it. "" when done, else why not.
  virtual std::string freeze(int endcap, bool loop_only) = 0;
  // An operator's command (estop, clear_fault, start), handed to the run's operator,
  // which sends it over DDS off the stepper's thread. "" when handed over, else why not.
  virtual std::string operator_command(const ScenarioEvent& event) {
    static_cast<void>(event);
    return "no operator in this run";
  }
};

// Takes an operator's command without blocking (HilOptions::operator_command).
using OperatorCommand = std::function<std::string(const ScenarioEvent&)>;

// The real thing: the roster's devices and programs, the hub's wire.
class LiveFaultTarget final : public FaultTarget {
 public:
  LiveFaultTarget(EndcapRoster& roster, UdpHub& hub) : roster_(roster), hub_(hub) {}
  int endcap_count() const override;
  EndcapDevices& devices(int endcap) override;
  void send(int endcap, const FrameOut& frames) override;
  void set_drop(int endcap, double probability) override { hub_.set_drop(endcap, probability); }
  void set_corrupt(int endcap, double probability, CorruptKind kind) override {
    hub_.set_corrupt(endcap, probability, kind);
  }
  void kill(int endcap) override;
  void restart(int endcap) override;
  std::string set_dds_link(int endcap, bool up) override;
  std::string mute_dds(int endcap) override;
  std::string freeze(int endcap, bool loop_only) override;
  std::string operator_command(const ScenarioEvent& event) override;
  void set_operator(OperatorCommand command) { operator_ = std::move(command); }

 private:
  EndcapRoster& roster_;
  UdpHub& hub_;
  OperatorCommand operator_;
};

class FaultInjector {
 public:
  FaultInjector() = default;
  FaultInjector(Scenario scenario, double dt_s) : scenario_(std::move(scenario)), dt_s_(dt_s) {}

  // At physics step `step` (device time `now_ns`): applies every event due by
  // then, in order, and ends the frame faults whose time is over. One line per
  // event applied goes to `log`. Throws HilError for an event the end cap cannot
  // take (a motor it does not have).
  void apply_due(std::int64_t step, std::int64_t now_ns, FaultTarget& target, std::vector<std::string>& log);

 private:
  struct FrameFault {
    int endcap;
    bool corrupt;
    std::int64_t until_step;  // -1: to the end
  };
  void apply(const ScenarioEvent& event, std::int64_t step, std::int64_t now_ns, FaultTarget& target,
             std::vector<std::string>& log);
  void apply_to_motors(const ScenarioEvent& event, std::int64_t now_ns, FaultTarget& target);
  void start_frame_fault(const ScenarioEvent& event, std::int64_t step, FaultTarget& target);
  void end_frame_faults(std::int64_t step, FaultTarget& target);
  static std::string apply_dds_link(const ScenarioEvent& event, FaultTarget& target);

  Scenario scenario_;
  double dt_s_ = 0.001;
  std::size_t next_event_ = 0;
  std::vector<FrameFault> frame_faults_;
  FrameOut out_;
};

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
#pragma once
// Drives the model's cables with one instance of the end caps' control core per end
// cap, exactly as the firmware plays a policy: the simulator never re-implements
// the table, the motor loop or the tension guard.
#include <cstdint>
#include <vector>

#include "core/endcap_controller.hpp"
#include "sim/model/controller.hpp"
#include "robot/policy.hpp"

namespace tensegrity::sim {

class CoreController final : public Controller {
 public:
  CoreController(const Robot& robot, const Policy& policy);
  void reset(const Robot& robot) override;
  void update(const ControlInput& input, std::span<double> preferred_rest_length_m) override;

  // Lets an experiment fault one end cap, e.g. a failed muscle.
  core::EndcapController& endcap(int index) { return endcaps_[index]; }

 private:
  struct Wiring {
    std::vector<int> cables;
  };
  std::vector<core::EndcapController> endcaps_;
  std::vector<core::EndcapTable> tables_;
  std::vector<Wiring> wiring_;
  // The first update sets each core's commanded lengths to the cables' rest lengths, as
  // an end cap takes its drives' positions at boot: an episode that starts from a
  // rolling robot's state goes on from its lengths rather than jumping to the initial ones.
  bool synced_ = false;
};

}  // namespace tensegrity::sim

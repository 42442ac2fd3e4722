// SPDX-License-Identifier: Apache-2.0
#pragma once
// A controller seen through imperfect hardware: its load cells read the tension plus
// a bias and seeded normal noise, and its commands reach the motors a fixed number of
// steps late. Wraps any controller; with no noise, bias or delay it changes nothing.
#include <cstdint>
#include <deque>
#include <vector>

#include "sim/model/controller.hpp"

namespace tensegrity::sim {

struct HardwareFaults {
  double load_cell_noise_n = 0.0;  // standard deviation
  double load_cell_bias_n = 0.0;
  std::uint64_t load_cell_seed = 0;
  double actuation_delay_s = 0.0;
};

class FaultyController final : public Controller {
 public:
  FaultyController(Controller& inner, const HardwareFaults& faults) : inner_(inner), faults_(faults) {}
  void reset(const Robot& robot) override;
  void update(const ControlInput& input, std::span<double> preferred_rest_length_m) override;

 private:
  double normal();  // a standard normal draw (Box-Muller on SplitMix64: the same on every platform)

  Controller& inner_;
  HardwareFaults faults_;
  std::uint64_t rng_ = 0;
  std::vector<double> read_n_;
  std::deque<std::vector<double>> pending_;  // commands given, oldest first
  std::vector<double> held_;                 // what the motors hold before the first command arrives
};

}  // namespace tensegrity::sim

// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/faulty_controller.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tensegrity::sim {

void FaultyController::reset(const Robot& robot) {
  inner_.reset(robot);
  rng_ = faults_.load_cell_seed;
  pending_.clear();
  held_.clear();
}

double FaultyController::normal() {
  const auto next = [this] {
    std::uint64_t z = (rng_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (static_cast<double>(z >> 11) + 0.5) * 0x1.0p-53;  // in (0, 1)
  };
  const double u1 = next();
  const double u2 = next();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

void FaultyController::update(const ControlInput& input, std::span<double> preferred) {
  ControlInput seen = input;
  if (faults_.load_cell_noise_n > 0.0 || faults_.load_cell_bias_n != 0.0) {
    read_n_.assign(input.tension_n.begin(), input.tension_n.end());
    for (double& t : read_n_) {
      t += faults_.load_cell_bias_n;
      if (faults_.load_cell_noise_n > 0.0) t += faults_.load_cell_noise_n * normal();
    }
    seen.tension_n = read_n_;
  }
  inner_.update(seen, preferred);
  const auto delay = static_cast<std::size_t>(std::llround(faults_.actuation_delay_s / input.dt_s));
  if (delay == 0) return;
  if (held_.empty()) held_.assign(input.rest_length_m.begin(), input.rest_length_m.end());
  pending_.emplace_back(preferred.begin(), preferred.end());
  if (pending_.size() > delay) {
    std::copy(pending_.front().begin(), pending_.front().end(), preferred.begin());
    pending_.pop_front();
  } else {
    std::copy(held_.begin(), held_.end(), preferred.begin());
  }
}

}  // namespace tensegrity::sim

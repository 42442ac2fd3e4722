// SPDX-License-Identifier: Apache-2.0
#include "sim/model/core_controller.hpp"

#include <array>

namespace tensegrity::sim {

CoreController::CoreController(const Robot& robot, const Policy& policy) {
  for (int e = 0; e < robot.endcap_count(); ++e) {
    Wiring w{robot.cables_of(e)};
    core::EndcapConfig config;
    config.motor_count = static_cast<std::uint32_t>(w.cables.size());
    config.limits = robot.motor;
    config.initial_rest_length_m = robot.initial_rest_length_m;
    endcaps_.emplace_back(config);
    tables_.push_back(endcap_table(policy, robot, e));
    wiring_.push_back(std::move(w));
  }
}

void CoreController::reset(const Robot&) {
  synced_ = false;
  for (std::size_t e = 0; e < endcaps_.size(); ++e) {
    auto& endcap = endcaps_[e];
    endcap.clear_fault();
    endcap.stop();
    const auto error = endcap.load(tables_[e]);
    if (error != core::TableError::none) {
      throw PolicyError("end cap " + std::to_string(e) + ": " + core::describe(error));
    }
    if (!wiring_[e].cables.empty()) endcap.start(0);
  }
}

void CoreController::update(const ControlInput& input, std::span<double> preferred) {
  // Integer time from the step count, as an end cap counts SYNC ticks.
  const std::int64_t dt_ns = core::seconds_to_ns(input.dt_s);
  const std::int64_t now_ns = input.step * dt_ns;
  std::array<double, core::kMaxMotorsPerEndcap> tension{};
  std::array<double, core::kMaxMotorsPerEndcap> commanded{};
  for (std::size_t e = 0; e < endcaps_.size(); ++e) {
    const auto& cables = wiring_[e].cables;
    if (cables.empty()) continue;
    for (std::size_t k = 0; k < cables.size(); ++k) tension[k] = input.tension_n[cables[k]];
    if (!synced_) {
      for (std::size_t k = 0; k < cables.size(); ++k) commanded[k] = input.rest_length_m[cables[k]];
      endcaps_[e].reset_commanded(std::span(commanded.data(), cables.size()));
    }
    endcaps_[e].step(now_ns, input.dt_s, std::span(tension.data(), cables.size()),
                     std::span(commanded.data(), cables.size()));
    for (std::size_t k = 0; k < cables.size(); ++k) preferred[cables[k]] = commanded[k];
  }
  synced_ = true;
}

}  // namespace tensegrity::sim

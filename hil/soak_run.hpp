// SPDX-License-Identifier: Apache-2.0
// The chaos soak (tensegrity soak, docs/guide/hil.md "Chaos soak"): one real-time HIL
// run over DDS (secured unless told otherwise) with a seeded random scenario of
// end-cap kills and restarts, link cuts, drive reboots and an operator's estops,
// clears and starts (soak_plan.hpp), its invariants checked throughout
// (soak_check.hpp), the result as JSON and as a summary.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stop_token>
#include <string>

#include <nlohmann/json.hpp>

#include "hil/hil_run.hpp"
#include "hil/soak_check.hpp"
#include "hil/soak_plan.hpp"

namespace tensegrity::hil {

struct SoakOptions {
  std::filesystem::path robot;  // empty: the policy's
  std::filesystem::path policy;
  double duration_s = 120.0;
  std::uint64_t seed = 1;
  int dds_domain = -1;                 // -1: a free one of the HIL's range
  std::filesystem::path dds_keystore;  // empty: unsecured
  double estop_bound_s = 0.5;
  double settle_s = 15.0;
  double mean_gap_s = 5.0;
  std::filesystem::path endcap_binary;  // empty: the default
  std::stop_token stop;
};

struct SoakResult {
  bool ok = false;  // the run completed and no invariant broke
  std::uint64_t seed = 0;
  double duration_s = 0.0;
  Scenario scenario;
  std::vector<SoakViolation> violations;
  nlohmann::json checks;  // SoakChecker::to_json()
  HilResult hil;
  std::vector<std::string> operator_log;
  // Its station's deletion hung: a thread is left running; end the process at once
  // (std::_Exit) after reporting, as static destructors may hang on it too.
  bool operator_hung = false;
  double load_average_start = 0.0, load_average_end = 0.0;  // 1-minute
};

// The scenario alone (for --plan): the robot's end caps and motors, the seed.
Scenario soak_scenario(const SoakOptions& options, const sim::Robot& robot);
SoakResult run_soak(const SoakOptions& options);
nlohmann::json to_json(const SoakResult& result);
std::string summary_text(const SoakResult& result);

}  // namespace tensegrity::hil

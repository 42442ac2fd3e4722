// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a policy file ("tensegrity-policy/1") as the simulator reads it
// (against the hardware robot, robots/superball.json, which the corpus's policies are
// for) and as an end cap reads its share of it.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "firmware/app/policy_file.hpp"
#include "core/limits.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"

namespace sim = tensegrity::sim;
namespace app = tensegrity::fw::app;

namespace {

const sim::Robot& robot() {
  static const sim::Robot r = sim::load_robot(sim::robot_path_named("superball"));
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sim::Policy policy = sim::parse_policy(text, robot(), "fuzz");
    for (int e = 0; e < robot().endcap_count(); ++e) (void)sim::endcap_table(policy, robot(), e);
  } catch (const sim::PolicyError&) {
  }
  for (int endcap = 0; endcap < 12; endcap += 5) {
    try {
      (void)app::endcap_table_from_policy(text, endcap, 2, tensegrity::core::MotorLimits{}, "fuzz");
    } catch (const app::PolicyFileError&) {
    }
  }
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The policy file ("tensegrity-policy/1"), read once for everyone who reads it: the
// simulator and the coevolution (robot/policy.hpp, which adds the robot's checks and
// the provenance), the end cap (firmware/app/policy_file.hpp, its share only), the
// ground tools and the HIL. The shape is checked here with field paths; rest-length
// limits are the reader's (an end cap checks its own cables against its own
// limits, and another end cap's cables are not its to judge).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/limits.hpp"
#include "core/table.hpp"

namespace tensegrity::format {

class PolicyFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kPolicyFormat = "tensegrity-policy/1";

struct PolicyCable {
  int cable = 0;  // index into the robot's cables
  int owner = 0;  // end cap whose motor drives it
  std::vector<double> rest_lengths_m;
};

struct PolicyDocument {
  std::string robot;  // empty when the file names none
  double period_s = 0.0;
  int complexity = 0;
  std::vector<PolicyCable> cables;  // in file order
  nlohmann::json provenance;        // null when absent; read by robot/policy.cpp
};

// Checks the format name, period (0, 3600] s, complexity 1..core::kMaxComplexity,
// and every cable entry: integer cable and owner, no cable twice, exactly
// `complexity` finite rest lengths. Errors: "source: cables[4].rest_lengths_m: ...".
PolicyDocument parse_policy_document(const std::string& json_text, const std::string& source);

// "source: cables[6].rest_lengths_m[3]: 1.2 m is outside the rest-length limits [0.6, 1.1] m"
// for the first value of entry `entry` (index in the file) outside `limits`.
void check_rest_lengths(const PolicyDocument& doc, std::size_t entry, const core::MotorLimits& limits,
                        const std::string& source);

// End cap `endcap_id`'s share, the cables it owns in increasing cable index (motor m
// plays the m-th), checked against `limits` and by core::validate.
core::EndcapTable endcap_table_of(const PolicyDocument& doc, int endcap_id, std::uint32_t motor_count,
                                  const core::MotorLimits& limits, const std::string& source);

}  // namespace tensegrity::format

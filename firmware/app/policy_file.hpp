// SPDX-License-Identifier: Apache-2.0
// This end cap's share of a policy file ("tensegrity-policy/1", written by the
// simulator: robot/policy.hpp), read by the one policy-format parser every process
// uses (format/policy_format.hpp). The share is the cables whose "owner" is this
// end cap, in increasing cable index (format::endcap_table_of, which the simulator's
// sim::endcap_table calls too), so motor m plays the same column everywhere.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "core/limits.hpp"
#include "core/table.hpp"

namespace tensegrity::fw::app {

class PolicyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Errors name the source and the field; the table is checked with core::validate.
core::EndcapTable endcap_table_from_policy(const std::string& json_text, int endcap_id, std::uint32_t motor_count,
                                           const core::MotorLimits& limits, const std::string& source = "policy");
core::EndcapTable load_endcap_table(const std::filesystem::path& path, int endcap_id, std::uint32_t motor_count,
                                    const core::MotorLimits& limits);

}  // namespace tensegrity::fw::app

// SPDX-License-Identifier: Apache-2.0
// The policy the HIL commands play when none is given: the shipped one in policies/,
// found in the working directory or the source tree the binary was built from.
#pragma once

#include <filesystem>
#include <string>

namespace tensegrity::cli {

inline constexpr const char* kShippedPolicy = "policies/superball-paper-t4-n5.json";

// `given` when not empty, else the shipped policy; CommandError (2) when it is missing.
std::filesystem::path shipped_policy_or(const std::string& given);

}  // namespace tensegrity::cli

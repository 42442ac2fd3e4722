// SPDX-License-Identifier: Apache-2.0
#include "cli/shipped_policy.hpp"

#include "cli/commands.hpp"

namespace tensegrity::cli {

std::filesystem::path shipped_policy_or(const std::string& given) {
  if (!given.empty()) return given;
  const std::filesystem::path name = kShippedPolicy;
  if (std::filesystem::exists(name)) return name;
#ifdef TENSEGRITY_SOURCE_DIR
  const std::filesystem::path in_source = std::filesystem::path(TENSEGRITY_SOURCE_DIR) / name;
  if (std::filesystem::exists(in_source)) return in_source;
#endif
  throw CommandError(ExitCode::usage, "no policy: " + name.string() + " not found; give one with --policy FILE");
}

}  // namespace tensegrity::cli

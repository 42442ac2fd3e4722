// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/policy_file.hpp"

#include <fstream>
#include <sstream>

#include "format/policy_format.hpp"

namespace tensegrity::fw::app {

core::EndcapTable endcap_table_from_policy(const std::string& json_text, int endcap_id, std::uint32_t motor_count,
                                           const core::MotorLimits& limits, const std::string& source) {
  try {
    const format::PolicyDocument doc = format::parse_policy_document(json_text, source);
    return format::endcap_table_of(doc, endcap_id, motor_count, limits, source);
  } catch (const format::PolicyFormatError& e) {
    throw PolicyFileError(e.what());
  }
}

core::EndcapTable load_endcap_table(const std::filesystem::path& path, int endcap_id, std::uint32_t motor_count,
                                    const core::MotorLimits& limits) {
  std::ifstream in(path);
  if (!in) throw PolicyFileError(path.string() + ": cannot open the policy file");
  std::ostringstream text;
  text << in.rdbuf();
  return endcap_table_from_policy(text.str(), endcap_id, motor_count, limits, path.string());
}

}  // namespace tensegrity::fw::app

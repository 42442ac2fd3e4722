// SPDX-License-Identifier: Apache-2.0
#include "hil/provisioner.hpp"

#include "hil/hil_error.hpp"
#include "hil/process_launcher.hpp"

namespace tensegrity::hil {

std::vector<std::string> LocalProvisioner::endcap_arguments(int, bool restart) const {
  // Local provisioning needs no host link.
  if (restart) return {"--no-dds", "--start-on-boot"};
  return {"--no-dds", "--policy", policy_.string(), "--start-on-boot"};
}

void LocalProvisioner::provision(const ProcessLauncher& launcher) {
  std::string missing;
  for (int e = 0; e < launcher.endcap_count(); ++e) {
    if (!launcher.started(e)) continue;
    if (launcher.log_text(e).find("loaded and stored") == std::string::npos) {
      missing += " " + std::to_string(e);
    }
  }
  if (!missing.empty()) throw HilError("policy not acknowledged by end cap(s)" + missing + " (see their logs)");
}

}  // namespace tensegrity::hil

// SPDX-License-Identifier: Apache-2.0
// The config file the launcher writes for one end cap, in the end cap's own schema
// (firmware/app/config.hpp): its bus on the hub, its drives, the robot's limits, and
// the silence timeouts of the stepping mode.
#pragma once

#include <cstdint>
#include <filesystem>

#include "firmware/app/config.hpp"
#include "hil/process_launcher.hpp"

namespace tensegrity::hil {

fw::app::EndcapAppConfig endcap_config(const LauncherConfig& lc, int motors, std::uint16_t port,
                                       const std::filesystem::path& store);

}  // namespace tensegrity::hil

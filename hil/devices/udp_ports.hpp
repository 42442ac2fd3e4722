// SPDX-License-Identifier: Apache-2.0
// Free UDP ports on 127.0.0.1 for emulated buses: the HIL launcher's end caps and
// the tests that start an `endcap` program by hand. Here, beside the emulated
// devices, so firmware-only (cross) test builds get it without the HIL and ODE.
#pragma once

#include <cstdint>
#include <vector>

namespace tensegrity::hil {

// Chosen from the kLauncherPortSpan ports just below the kernel's ephemeral range
// (bound together, then released); throws std::runtime_error if too few are free.
inline constexpr int kLauncherPortSpan = 2048;
std::vector<std::uint16_t> free_udp_ports(int count);

}  // namespace tensegrity::hil

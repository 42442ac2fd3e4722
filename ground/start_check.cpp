// SPDX-License-Identifier: Apache-2.0
#include "ground/start_check.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "core/endcap_controller.hpp"
#include "ground/status.hpp"

namespace tensegrity::ground {

namespace {
constexpr auto kRunning = static_cast<std::uint8_t>(core::Mode::running);  // Telemetry_::mode
}

std::vector<PlayingCheck> check_playing(const std::array<EndcapStatus, kEndcapCount>& status, std::uint16_t mask,
                                        std::int64_t start_ns) {
  std::vector<PlayingCheck> out;
  for (int e = 0; e < kEndcapCount; ++e) {
    if ((mask & (1U << e)) == 0) continue;
    const EndcapStatus& s = status[static_cast<std::size_t>(e)];
    PlayingCheck c;
    c.endcap = e;
    c.heard = s.have_telemetry && s.telemetry.host_time_ns() >= start_ns;
    c.playing = c.heard && s.telemetry.mode() == kRunning;
    if (c.heard) {
      c.state = std::string(mode_name(s.telemetry.mode()));
      if (s.telemetry.fault() != 0) c.state += std::string(", fault ") + fault_name(s.telemetry.fault());
      if (!s.telemetry.drives_enabled()) c.state += ", drives not enabled";
    } else {
      c.state = "no telemetry since the start time";
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<PlayingCheck> wait_playing(const Station& station, std::uint16_t mask, std::int64_t start_ns,
                                       std::int64_t deadline_ns) {
  for (;;) {
    std::vector<PlayingCheck> checks = check_playing(station.snapshot(), mask, start_ns);
    if (all_playing(checks) || Station::now_ns() >= deadline_ns) return checks;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

bool all_playing(const std::vector<PlayingCheck>& checks) {
  return std::all_of(checks.begin(), checks.end(), [](const PlayingCheck& c) { return c.playing; });
}

std::string format_playing(const std::vector<PlayingCheck>& checks) {
  std::string out;
  int playing = 0;
  for (const PlayingCheck& c : checks) {
    if (c.playing) {
      ++playing;
    } else {
      out += "end cap " + std::to_string(c.endcap) + ": NOT playing (" + c.state + ")\n";
    }
  }
  return std::to_string(playing) + " of " + std::to_string(checks.size()) + " end caps playing\n" + out;
}

}  // namespace tensegrity::ground

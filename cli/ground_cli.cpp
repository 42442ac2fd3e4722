// SPDX-License-Identifier: Apache-2.0
#include "cli/ground_cli.hpp"

#include "cli/commands.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::cli {

void add_ground_options(CLI::App& cmd, GroundOptions& options, double default_timeout_s) {
  options.timeout_s = default_timeout_s;
  cmd.add_option("--domain", options.domain, "DDS domain id (default: TENSEGRITY_DOMAIN or 42)")
      ->check(CLI::Range(0, 232));
  cmd.add_option("--timeout", options.timeout_s, "Seconds to wait for every end cap")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd.add_option("--endcaps", options.endcaps, "End caps addressed, e.g. 0-11 or 0,3,5-7")->capture_default_str();
}

std::uint16_t parse_endcap_set(const std::string& text) {
  std::uint16_t mask = 0;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = text.find(',', at);
    const std::string part = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    try {
      std::size_t used = 0;
      const std::size_t dash = part.find('-');
      const int lo = std::stoi(part.substr(0, dash), &used);
      const int hi = dash == std::string::npos ? lo : std::stoi(part.substr(dash + 1));
      if (lo < 0 || hi >= ground::kEndcapCount || lo > hi) throw std::out_of_range(part);
      for (int i = lo; i <= hi; ++i) mask = static_cast<std::uint16_t>(mask | (1U << i));
    } catch (const std::exception&) {
      throw CommandError(2, "--endcaps '" + text + "': bad part '" + part + "' (end caps are 0..11)");
    }
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return mask;
}

std::unique_ptr<ground::Station> make_station(const GroundOptions& options, bool publish_heartbeat) {
  ground::StationOptions s;
  s.domain = options.domain >= 0 ? options.domain : msgs::domain_id();
  s.name = "tensegrity-cli";
  s.publish_heartbeat = publish_heartbeat;
  return std::make_unique<ground::Station>(s);
}

bool wait_for_endcaps(ground::Station& station, const GroundOptions& options, bool synced) {
  const auto deadline = ground::Station::now_ns() + static_cast<std::int64_t>(options.timeout_s * 1e9);
  return station.wait_for_endcaps(parse_endcap_set(options.endcaps), synced, deadline);
}

}  // namespace tensegrity::cli

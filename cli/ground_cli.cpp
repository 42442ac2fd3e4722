// SPDX-License-Identifier: Apache-2.0
#include "cli/ground_cli.hpp"

#include <cstdlib>

#include "cli/commands.hpp"
#include "msgs/dds.hpp"
#include "msgs/security.hpp"

namespace tensegrity::cli {

void add_ground_options(CLI::App& cmd, GroundOptions& options, double default_timeout_s) {
  options.timeout_s = default_timeout_s;
  cmd.add_option("--domain", options.domain, "DDS domain id (default: TENSEGRITY_DOMAIN or 42)")
      ->check(CLI::Range(0, 232));
  cmd.add_option("--timeout", options.timeout_s, "Seconds to wait for every end cap")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd.add_option("--endcaps", options.endcaps, "End caps addressed, e.g. 0-11 or 0,3,5-7")->capture_default_str();
  add_security_options(cmd, options.keystore, options.insecure);
}

void add_security_options(CLI::App& cmd, std::string& keystore, bool& insecure) {
  auto* k = cmd.add_option("--keystore", keystore,
                           "DDS Security keystore (tensegrity security init): speak with its ground identity "
                           "(default: TENSEGRITY_KEYSTORE, else ~/.local/share/tensegrity/keystore)");
  auto* i = cmd.add_flag("--insecure", insecure, "Unauthenticated, unencrypted DDS: only when asked, never a fallback");
  k->excludes(i);
}

// Secured end caps refuse an unsecured participant, so a tool that fell back to
// no security would wait its whole timeout and report every end cap missing: it
// stops at once instead, and unsecured is asked for by name (--insecure).
std::filesystem::path tool_enclave(msgs::Role role, const std::string& keystore, bool insecure) {
  if (insecure) return {};
  // The default keystore is the one `tensegrity hil` makes and uses: when it is
  // there, the tools speak with it, so they hear a HIL run without flags.
  const char* env = std::getenv("TENSEGRITY_KEYSTORE");
  const bool named = !keystore.empty() || (env != nullptr && *env != '\0');
  const std::filesystem::path store = keystore.empty() ? msgs::default_keystore() : std::filesystem::path(keystore);
  const std::filesystem::path dir = msgs::enclave_dir(store, msgs::enclave_name(role));
  if (std::filesystem::exists(dir)) return dir;
  const std::string where =
      named ? "no DDS Security keystore at " + store.string()
            : "no DDS Security keystore named (--keystore, TENSEGRITY_KEYSTORE) and none at " + store.string();
  throw CommandError(ExitCode::usage,
                     where + ": create one with `tensegrity security init " + store.string() +
                         "` (and give each end cap its enclave), name another with --keystore DIR or "
                         "TENSEGRITY_KEYSTORE, or pass --insecure to speak to end caps that run without security "
                         "(docs/guide/security.md)");
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
      throw CommandError(ExitCode::usage, "--endcaps '" + text + "': bad part '" + part + "' (end caps are 0..11)");
    }
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return mask;
}

ground::StationOptions station_options(const GroundOptions& options, bool publish_heartbeat) {
  ground::StationOptions s;
  s.domain = options.domain >= 0 ? options.domain : msgs::domain_id();
  s.name = "tensegrity-cli";
  s.publish_heartbeat = publish_heartbeat;
  s.enclave_dir = tool_enclave(msgs::Role::ground, options.keystore, options.insecure);
  return s;
}

std::unique_ptr<ground::Station> make_station(const GroundOptions& options, bool publish_heartbeat) {
  return std::make_unique<ground::Station>(station_options(options, publish_heartbeat));
}

bool wait_for_endcaps(ground::Station& station, const GroundOptions& options, bool synced) {
  const auto deadline = ground::Station::now_ns() + static_cast<std::int64_t>(options.timeout_s * 1e9);
  return station.wait_for_endcaps(parse_endcap_set(options.endcaps), synced, deadline);
}

}  // namespace tensegrity::cli

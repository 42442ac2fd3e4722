// SPDX-License-Identifier: Apache-2.0
// Options every ground subcommand shares (DDS domain, end-cap set, timeout), and
// the translation of a ground report into the exit code.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "ground/station.hpp"
#include "msgs/security.hpp"

namespace tensegrity::cli {

struct GroundOptions {
  int domain = -1;  // -1: TENSEGRITY_DOMAIN or the default
  double timeout_s = 5.0;
  std::string endcaps = "0-11";
  // DDS Security: the keystore whose ground enclave this tool speaks with (empty:
  // msgs::default_keystore()); `insecure` speaks unauthenticated, explicitly.
  std::string keystore;
  bool insecure = false;
};

// The enclave of `role` (ground, or listener for read-only tools) in `keystore`, or
// in the default keystore (msgs::default_keystore); empty (unsecured) only with
// `insecure`. Throws CommandError(ExitCode::usage), saying how to get one, when there is none.
std::filesystem::path tool_enclave(msgs::Role role, const std::string& keystore, bool insecure);
void add_security_options(CLI::App& cmd, std::string& keystore, bool& insecure);

void add_ground_options(CLI::App& cmd, GroundOptions& options, double default_timeout_s);
// "0-11", "3", "0,2,5-7" -> mask; throws CommandError(ExitCode::usage) naming the bad part.
std::uint16_t parse_endcap_set(const std::string& text);
// What make_station builds (the enclave resolved once: a tool that rejoins makes
// several stations from it).
ground::StationOptions station_options(const GroundOptions& options, bool publish_heartbeat = true);
std::unique_ptr<ground::Station> make_station(const GroundOptions& options, bool publish_heartbeat = true);
// Waits (up to the timeout) for the addressed end caps' heartbeats so that a
// command is not sent into discovery; returns false when some are missing.
bool wait_for_endcaps(ground::Station& station, const GroundOptions& options, bool synced);

}  // namespace tensegrity::cli

// SPDX-License-Identifier: Apache-2.0
// What a ground tool and a running operator console (`tensegrity console`) say over
// the console's local socket: one request line and one reply line, JSON, typed here
// on both sides. The console is a ground station that authenticated with the end
// caps once and stays up, so a command it relays lands in milliseconds where a fresh
// secured tool pays seconds of DDS Security handshakes first (docs/guide/security.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "ground/command.hpp"

namespace tensegrity::ground {

inline constexpr const char* kOperatorFormat = "tensegrity-operator/1";
// The longest deadline a console takes for one command.
inline constexpr double kMaxOperatorTimeoutS = 3600.0;

class OperatorLinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OperatorRequest {
  CommandKind kind = CommandKind::emergency_stop;  // estop, stop or clear-fault (start needs a time plan)
  std::uint16_t endcap_mask = kAllEndcaps;
  double timeout_s = 30.0;  // the console's deadline for the last acknowledgement
};

struct OperatorReply {
  std::string error;  // non-empty: the console refused the request (and says why)
  CommandReport report;
  long console_pid = 0;
};

std::string encode_request(const OperatorRequest& request);
// Throws OperatorLinkError naming the field ("request: timeout_s: must be > 0").
OperatorRequest decode_request(const std::string& line);
std::string encode_reply(const OperatorReply& reply);
OperatorReply decode_reply(const std::string& line);

// Where the console of `domain` listens: $XDG_RUNTIME_DIR/tensegrity/console-<domain>.sock,
// else /tmp/tensegrity-<uid>/console-<domain>.sock; a folder only its user may enter.
std::filesystem::path default_console_socket(int domain);

}  // namespace tensegrity::ground

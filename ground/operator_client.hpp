// SPDX-License-Identifier: Apache-2.0
// A ground tool's side of the operator console's socket (operator_protocol.hpp).
#pragma once

#include <filesystem>
#include <optional>

#include "ground/operator_protocol.hpp"

namespace tensegrity::ground {

// The reply of the console listening at `socket_path`, or nullopt when none does
// (no socket there, or one left by a console that died): the tool then speaks on
// its own. Throws OperatorLinkError when a console answered but not as expected.
std::optional<OperatorReply> ask_console(const std::filesystem::path& socket_path, const OperatorRequest& request);

}  // namespace tensegrity::ground

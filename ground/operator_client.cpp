// SPDX-License-Identifier: Apache-2.0
#include "ground/operator_client.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "ground/unix_socket.hpp"

namespace tensegrity::ground {

std::optional<OperatorReply> ask_console(const std::filesystem::path& socket_path, const OperatorRequest& request) {
  const std::filesystem::path socket = std::filesystem::absolute(socket_path).lexically_normal();
  std::error_code missing;
  if (!std::filesystem::exists(socket.parent_path(), missing)) return std::nullopt;
  UniqueFd fd;
  try {
    // Only a socket in this user's private folder, served by this user, is the
    // console: anything else could answer "all accepted" to a stop it never sent.
    check_private_folder(socket.parent_path());
    fd = connect_unix(socket);
  } catch (const std::runtime_error& e) {
    throw OperatorLinkError(e.what());
  }
  if (!fd) {
    if (errno == ENOENT || errno == ECONNREFUSED) return std::nullopt;
    throw OperatorLinkError(socket.string() + ": cannot reach the console: " + std::strerror(errno));
  }
  if (peer_uid(fd.get()) != static_cast<long>(::geteuid())) {
    throw OperatorLinkError(socket.string() + ": served by another user, not taken for a console");
  }
  // The console answers when the last end cap acked or at the request's deadline.
  const auto wait = std::chrono::milliseconds(static_cast<long>(request.timeout_s * 1e3) + 5000);
  try {
    write_all(fd.get(), encode_request(request) + "\n");
    return decode_reply(read_line(fd.get(), 1U << 16, wait));
  } catch (const OperatorLinkError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw OperatorLinkError(socket.string() + ": console: " + e.what());
  }
}

}  // namespace tensegrity::ground

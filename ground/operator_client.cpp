// SPDX-License-Identifier: Apache-2.0
#include "ground/operator_client.hpp"

#include <cerrno>
#include <cstring>
#include <chrono>
#include <stdexcept>

#include "ground/unix_socket.hpp"

namespace tensegrity::ground {

std::optional<OperatorReply> ask_console(const std::filesystem::path& socket_path, const OperatorRequest& request) {
  UniqueFd fd;
  try {
    fd = connect_unix(socket_path);
  } catch (const std::runtime_error& e) {  // a path no socket can have
    throw OperatorLinkError(e.what());
  }
  if (!fd) {
    if (errno == ENOENT || errno == ECONNREFUSED) return std::nullopt;
    throw OperatorLinkError(socket_path.string() + ": cannot reach the console: " + std::strerror(errno));
  }
  // The console answers when the last end cap acked or at the request's deadline.
  const auto wait = std::chrono::milliseconds(static_cast<long>(request.timeout_s * 1e3) + 5000);
  try {
    write_all(fd.get(), encode_request(request) + "\n");
    return decode_reply(read_line(fd.get(), 1U << 16, wait));
  } catch (const OperatorLinkError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw OperatorLinkError(socket_path.string() + ": console: " + e.what());
  }
}

}  // namespace tensegrity::ground

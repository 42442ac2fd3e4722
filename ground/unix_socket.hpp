// SPDX-License-Identifier: Apache-2.0
// The few Unix-domain stream socket calls the operator console's link needs, with
// errors that name the path. By hand: no Debian library wraps local sockets for
// C++ without bringing an event loop, and this is four calls.
#pragma once

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

namespace tensegrity::ground {

// An open file descriptor, closed with its owner.
class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  ~UniqueFd();
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }
  explicit operator bool() const { return fd_ >= 0; }

 private:
  int fd_;
};

// Connected, or an invalid fd with errno set (ENOENT: no socket, ECONNREFUSED: no
// one listens on it).
UniqueFd connect_unix(const std::filesystem::path& path);
// Listening on `path` (mode 0600; a stale socket there is replaced). Throws
// std::runtime_error naming the path when a live listener holds it or it is not a socket.
UniqueFd listen_unix(const std::filesystem::path& path, int backlog);
// Throws std::runtime_error naming the folder unless it is a real directory (not a
// symbolic link) owned by this user that nobody else may enter (no group or other
// permission bits): what keeps another user's socket from passing as ours.
void check_private_folder(const std::filesystem::path& folder);
// The uid of the peer of a connected socket (SO_PEERCRED), or -1.
long peer_uid(int fd);
// The peer closed the connection before sending anything (a liveness probe).
class PeerClosed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One '\n'-terminated line (without it), at most `max_bytes`; throws PeerClosed
// when the peer closed before its first byte, std::runtime_error on a timeout, a
// peer that closed mid-line or a longer line.
std::string read_line(int fd, std::size_t max_bytes, std::chrono::milliseconds timeout);
// All of `text`, or throws std::runtime_error.
void write_all(int fd, const std::string& text);

}  // namespace tensegrity::ground

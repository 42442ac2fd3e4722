// SPDX-License-Identifier: Apache-2.0
#include "ground/unix_socket.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace tensegrity::ground {
namespace {

sockaddr_un address(const std::filesystem::path& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.native().size() >= sizeof addr.sun_path) {
    throw std::runtime_error(path.string() + ": a socket path must be shorter than " +
                             std::to_string(sizeof addr.sun_path) + " bytes");
  }
  std::memcpy(addr.sun_path, path.c_str(), path.native().size());
  return addr;
}

std::string system_error(const std::filesystem::path& path, const char* what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}

}  // namespace

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) ::close(fd_);
}

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

UniqueFd connect_unix(const std::filesystem::path& path) {
  const sockaddr_un addr = address(path);
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd) return fd;
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int saved = errno;
    fd = UniqueFd();
    errno = saved;
  }
  return fd;
}

UniqueFd listen_unix(const std::filesystem::path& path, int backlog) {
  const sockaddr_un addr = address(path);
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) throw std::runtime_error(path.string() + ": exists and is not a socket");
    if (connect_unix(path)) throw std::runtime_error(path.string() + ": another console already listens here");
    ::unlink(path.c_str());  // left by a process that died
  }
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd) throw std::runtime_error(system_error(path, "socket"));
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    throw std::runtime_error(system_error(path, "bind"));
  }
  if (::chmod(path.c_str(), 0600) != 0 || ::listen(fd.get(), backlog) != 0) {
    throw std::runtime_error(system_error(path, "listen"));
  }
  return fd;
}

void check_private_folder(const std::filesystem::path& folder) {
  struct stat st {};
  if (::lstat(folder.c_str(), &st) != 0) throw std::runtime_error(system_error(folder, "lstat"));
  if (!S_ISDIR(st.st_mode)) throw std::runtime_error(folder.string() + ": not a directory (a link is not accepted)");
  if (st.st_uid != ::geteuid()) throw std::runtime_error(folder.string() + ": belongs to another user");
  if ((st.st_mode & 077) != 0) {
    throw std::runtime_error(folder.string() + ": others may enter it (chmod 700 it, or pick a private folder)");
  }
}

long peer_uid(int fd) {
  ucred cred{};
  socklen_t size = sizeof cred;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &size) != 0) return -1;
  return static_cast<long>(cred.uid);
}

std::string read_line(int fd, std::size_t max_bytes, std::chrono::milliseconds timeout) {
  std::string line;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  char c = 0;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) {
      throw std::runtime_error("no complete line within " + std::to_string(timeout.count()) + " ms");
    }
    const ssize_t n = ::read(fd, &c, 1);
    if (n == 0 && line.empty()) throw PeerClosed("the peer closed the connection");
    if (n == 0) throw std::runtime_error("the peer closed the connection mid-line");
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string("read: ") + std::strerror(errno));
    }
    if (c == '\n') return line;
    if (line.size() >= max_bytes) throw std::runtime_error("line longer than " + std::to_string(max_bytes) + " bytes");
    line.push_back(c);
  }
}

void write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::send(fd, text.data() + done, text.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("write: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace tensegrity::ground

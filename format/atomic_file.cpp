// SPDX-License-Identifier: Apache-2.0
#include "format/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace tensegrity::format {
namespace {

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path) {
  throw std::system_error(errno, std::generic_category(), what + " " + path.string());
}

// Closes `fd`, removes the temporary and throws, keeping the first error's errno.
[[noreturn]] void abandon(int fd, const std::filesystem::path& tmp, const std::string& what) {
  const int saved = errno;
  if (fd >= 0) ::close(fd);
  ::unlink(tmp.c_str());
  errno = saved;
  fail(what, tmp);
}

}  // namespace

void fsync_directory(const std::filesystem::path& dir) {
  const std::filesystem::path d = dir.empty() ? std::filesystem::path(".") : dir;
  const int fd = ::open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail("cannot open directory", d);
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) fail("cannot fsync directory", d);
}

void write_file_atomic(const std::filesystem::path& path, const std::string& content, Durability durability) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("cannot create", tmp);
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon(fd, tmp, "cannot write");
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  const bool synced = durability == Durability::synced;
  if (synced && ::fsync(fd) != 0) abandon(fd, tmp, "cannot fsync");
  if (::close(fd) != 0) abandon(-1, tmp, "cannot close");
  if (::rename(tmp.c_str(), path.c_str()) != 0) abandon(-1, tmp, "cannot rename onto " + path.string() + " from");
  if (synced) fsync_directory(path.parent_path());
}

}  // namespace tensegrity::format

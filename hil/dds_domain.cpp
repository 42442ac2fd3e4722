// SPDX-License-Identifier: Apache-2.0
#include "hil/dds_domain.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {

// The lock file's descriptor when `domain` was free (now held), else -1.
int try_lease(int domain) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("tensegrity-hil-domain-" + std::to_string(domain) + ".lock");
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) throw HilError("DDS domain lease: " + path.string() + ": " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

DomainLease::DomainLease(int wanted) {
  if (wanted >= 0) {
    if (wanted > kLastHilDomain) throw HilError("DDS domain " + std::to_string(wanted) + ": expected 0..232");
    fd_ = try_lease(wanted);
    if (fd_ < 0) throw HilError("DDS domain " + std::to_string(wanted) + " is in use by another HIL run");
    domain_ = wanted;
    return;
  }
  for (int d = kFirstHilDomain; d <= kLastHilDomain; ++d) {
    fd_ = try_lease(d);
    if (fd_ >= 0) {
      domain_ = d;
      return;
    }
  }
  throw HilError("no free DDS domain in " + std::to_string(kFirstHilDomain) + ".." + std::to_string(kLastHilDomain) +
                 " (every one is held by a running HIL)");
}

DomainLease::~DomainLease() {
  if (fd_ >= 0) ::close(fd_);  // closing drops the flock
}

}  // namespace tensegrity::hil

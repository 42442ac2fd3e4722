// SPDX-License-Identifier: Apache-2.0
// A DDS domain of its own for one HIL run: its end caps and its host must not
// hear another run's (parallel tests, two people on one machine) nor a real robot
// on the default domain 42. Domains 215..232 are leased with an flock()ed file
// each in the temp directory: the kernel drops the lock when the process ends,
// however it ends, so a crashed run never keeps its domain. Their RTPS ports
// (7400 + 250 x domain + ..., 61150 and up) lie above Linux's ephemeral range
// (32768..60999) and the 2048 ports below it, where the HIL picks its CAN-over-UDP
// ports (hil/process_launcher): a lower domain's participants once took a port the
// launcher had just picked for an end cap's bus.
#pragma once

#include <filesystem>

namespace tensegrity::hil {

inline constexpr int kFirstHilDomain = 215;
inline constexpr int kLastHilDomain = 232;

class DomainLease {
 public:
  // `wanted` >= 0: that domain (an error if another run holds it); -1: the first free one.
  // Throws HilError when none is free.
  explicit DomainLease(int wanted = -1);
  ~DomainLease();
  DomainLease(const DomainLease&) = delete;
  DomainLease& operator=(const DomainLease&) = delete;
  int domain() const { return domain_; }

 private:
  int domain_ = -1;
  int fd_ = -1;
};

}  // namespace tensegrity::hil

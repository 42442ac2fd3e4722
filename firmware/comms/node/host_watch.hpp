// SPDX-License-Identifier: Apache-2.0
// Whether a host watches this end cap: its heartbeats, and host loss when none
// came for host_timeout_s (host_boot_grace_s from the node's start before the
// first one, so an end cap started on boot that never hears a host does not roll
// on unwatched). With the action `stop`, a lost host asks the loop to stop through
// a counter the loop reads every cycle, like the emergency stop: never refused by
// a full mailbox. Node thread, node clock; stops() from any thread.
#pragma once

#include <atomic>
#include <cstdint>

#include "firmware/comms/node/node_config.hpp"
#include "firmware/comms/node/node_log.hpp"

namespace tensegrity::fw::comms {

class HostWatch {
 public:
  HostWatch(double timeout_s, double boot_grace_s, HostLossAction action, std::uint16_t format_version,
            const NodeLog& log);

  void start(std::int64_t now_ns) { started_ns_ = now_ns; }
  // Whether a host heartbeat of this format counts; refusals are logged now and then.
  bool accepts(std::uint16_t format_version);
  void heard(std::int64_t now_ns);
  // Judges the silence; true when the host was lost in this call.
  bool poll(std::int64_t now_ns);

  bool seen() const { return seen_; }
  bool lost() const { return lost_; }
  // Heard for the first time, or again after a loss: a host that is not known to be the last one.
  bool fresh() const { return !seen_ || lost_; }
  std::int64_t last_heard_ns() const { return last_heard_ns_; }
  std::uint32_t stops() const noexcept { return stops_.load(std::memory_order_acquire); }
  std::uint64_t losses() const noexcept { return losses_.load(std::memory_order_relaxed); }
  std::uint64_t returns() const noexcept { return returns_.load(std::memory_order_relaxed); }

 private:
  std::int64_t timeout_ns_;
  std::int64_t boot_grace_ns_;
  HostLossAction action_;
  std::uint16_t format_version_;
  const NodeLog& log_;
  std::int64_t started_ns_ = 0;
  std::int64_t last_heard_ns_ = 0;
  bool seen_ = false;
  bool lost_ = false;
  std::uint64_t refused_format_ = 0;
  std::atomic<std::uint32_t> stops_{0};
  std::atomic<std::uint64_t> losses_{0}, returns_{0};
};

}  // namespace tensegrity::fw::comms

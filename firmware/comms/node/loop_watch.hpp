// SPDX-License-Identifier: Apache-2.0
// The loop-progress watchdog, the one place that decides whether the control loop
// is alive for the heartbeat: a hung loop must look dead to the host, so the node
// withholds its heartbeat while the loop's progress counter stands still for
// loop_stall_timeout_s. Node thread, node clock; stalls() from any thread.
#pragma once

#include <atomic>
#include <cstdint>

#include "firmware/comms/node/node_log.hpp"

namespace tensegrity::fw::comms {

class LoopWatch {
 public:
  // `progress` null: no watchdog, the loop always counts as alive.
  LoopWatch(const std::atomic<std::uint64_t>* progress, double stall_timeout_s, const NodeLog& log);

  void start(std::int64_t now_ns) { progress_ns_ = now_ns; }
  // Reads the counter; logs a change of state.
  bool alive(std::int64_t now_ns);
  // As last judged by alive().
  bool stalled() const { return stalled_; }
  std::uint64_t stalls() const noexcept { return stalls_.load(std::memory_order_relaxed); }

 private:
  const std::atomic<std::uint64_t>* progress_;
  std::int64_t stall_timeout_ns_;
  const NodeLog& log_;
  std::uint64_t progress_seen_ = 0;
  std::int64_t progress_ns_ = 0;  // when the counter last moved
  bool stalled_ = false;
  std::atomic<std::uint64_t> stalls_{0};
};

// Fault injection from outside the node (a signal handler flips the flags, HIL):
// a cut link, said in the log on the node thread so it shows when the link went and
// came back; and muting, asked by a growing counter.
class LinkFaultWatch {
 public:
  // Either may be null: that fault is never injected.
  LinkFaultWatch(const std::atomic<bool>* link_cut, const std::atomic<std::uint32_t>* mute_requests, const NodeLog& log)
      : link_cut_(link_cut), mute_requests_(mute_requests), log_(log) {}

  // Logs a cut or a restored link; true when a new mute was asked for, which the
  // node applies to the participant of the moment only: the fault is a stalled
  // handshake, which belongs to a participant, not to the link.
  bool poll();
  std::uint64_t cuts() const noexcept { return cuts_.load(std::memory_order_relaxed); }

 private:
  const std::atomic<bool>* link_cut_;
  const std::atomic<std::uint32_t>* mute_requests_;
  const NodeLog& log_;
  bool was_cut_ = false;
  std::uint32_t mutes_seen_ = 0;
  std::atomic<std::uint64_t> cuts_{0};
};

}  // namespace tensegrity::fw::comms

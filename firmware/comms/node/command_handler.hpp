// SPDX-License-Identifier: Apache-2.0
// Commands, on Fast DDS's receive thread: the gate (command_gate.hpp) judges each
// sample, and what it delivers is acted on here at once. An emergency stop is a
// counter the loop reads every cycle: it waits for nothing (not for the node thread
// storing a table, not for room in a mailbox) and is acked as soon as it is
// latched. A start is mapped onto the loop's clock here and judged against the
// loop's readiness, so the ack says why a start cannot run rather than the loop
// finding out a cycle later, unseen. No DDS: the node reads the samples and sends
// the answers.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>

#include "firmware/app/host_link.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/comms/logic/command_gate.hpp"
#include "firmware/comms/node/node_log.hpp"
#include "firmware/comms/node/shared_time_sync.hpp"
#include "firmware/comms/logic/start_readiness.hpp"
#include "firmware/comms/logic/start_time.hpp"

namespace tensegrity::fw::comms {

// The loop's clock and readiness at one of its cycles, as the loop publishes it.
struct LoopPoint {
  LoopClockPoint clock;
  LoopReadiness ready;
};

class CommandHandler {
 public:
  static constexpr std::size_t kMailboxCapacity = 16;

  // `life_id` (never 0, a host's value) names this life's estop count on the wire,
  // so a clear-fault that saw an earlier life's count cannot match.
  CommandHandler(int endcap_id, std::uint16_t format_version, std::int64_t max_age_ns, std::int64_t start_grid_ns,
                 std::uint32_t life_id, const NodeLog& log);

  // One sample, judged and acted on; the answer to ack, or nothing (addressed to
  // other end caps: no ack). `sync` as read once for this sample, `now_ns` the node
  // clock. Calls must not overlap (the node serializes its listeners).
  std::optional<CommandReason> handle(const CommandSample& c, const SyncView& sync, std::int64_t now_ns);

  // The control loop's thread: lock-free, no allocation.
  void note_loop(const LoopPoint& point) noexcept { loop_in_.write(point); }
  bool take(app::HostCommand& out) noexcept { return commands_.pop(out); }

  // Any thread.
  std::uint32_t estops() const noexcept { return estops_.load(std::memory_order_acquire); }
  std::uint32_t life_id() const noexcept { return life_id_; }

 private:
  CommandReason act_on(const CommandSample& c, WireCommandKind kind, const SyncView& sync);
  CommandReason map_start(const CommandSample& c, const SyncView& sync, app::HostCommand& out);

  CommandGate gate_;
  StartTimeMapper start_mapper_;
  std::uint16_t format_version_;
  std::uint32_t life_id_;
  const NodeLog& log_;
  app::SpscRing<app::HostCommand, kMailboxCapacity> commands_;  // producer: handle() only
  app::LatestValue<LoopPoint> loop_in_;
  // The loop's latest cycle as last read: a start is mapped and judged here, and the
  // node thread's last look at the loop may be many cycles old (lockstep runs its
  // cycles faster than the node wakes).
  LoopPoint loop_point_{};
  bool loop_point_valid_ = false;
  std::atomic<std::uint32_t> estops_{0};
};

}  // namespace tensegrity::fw::comms

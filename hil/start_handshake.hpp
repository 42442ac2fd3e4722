// SPDX-License-Identifier: Apache-2.0
// The hand-over between a provisioner that talks to the end caps over DDS (its own
// thread: upload, start command) and the world stepper, which must keep serving
// the end caps' buses meanwhile: drives enabled, physics frozen at the start
// state ("hold"). The provisioner ends the hold with the moment of physics step 0.
//
// Lockstep: loop time on an end cap is its SYNC count, so "start at host time T"
// only means something against a SYNC whose send time is known. The provisioner
// asks the stepper to freeze (no more SYNCs); the stepper reports when it sent the
// last one (and when every answer to it was in). Each end cap maps T = that send
// time + k ticks to its own loop time through the time sync (error: the mapping's
// latency and the sync error, well under half a tick) and, in lockstep, rounds it
// to its tick grid: every end cap starts on the k-th SYNC after the freeze, which
// the stepper makes physics step 0.
// Real time: the provisioner picks T a little ahead; physics step 0 is at T.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

namespace tensegrity::hil {

struct FrozenTick {
  std::int64_t sent_ns = 0;      // CLOCK_MONOTONIC just before the last SYNC went out
  std::int64_t answered_ns = 0;  // every live end cap's targets for it had arrived
};

class StartHandshake {
 public:
  // --- provisioner's thread ---
  // Lockstep: blocks until the stepper has stopped sending SYNC (or the deadline,
  // CLOCK_MONOTONIC: throws HilError).
  FrozenTick freeze(std::int64_t deadline_ns);
  // Lockstep: physics step 0 is the `ticks`-th SYNC after the freeze (ticks >= 1).
  void go_after_ticks(std::int64_t ticks);
  // Real time: physics step 0 at CLOCK_MONOTONIC `time_ns`.
  void go_at(std::int64_t time_ns);
  // The start cannot happen: the stepper ends the hold with HilError(reason).
  void fail(const std::string& reason);

  // --- stepper's thread ---
  bool freeze_requested() const;
  void frozen(const FrozenTick& tick);
  struct Decision {
    bool failed = false;
    std::string reason;
    std::int64_t after_ticks = 0;  // lockstep
    std::int64_t at_ns = 0;        // real time
  };
  // The decision if there is one; waits for it at most until `deadline_ns`.
  std::optional<Decision> decision(std::int64_t deadline_ns) const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  bool freeze_requested_ = false;
  std::optional<FrozenTick> frozen_;
  std::optional<Decision> decision_;
};

}  // namespace tensegrity::hil

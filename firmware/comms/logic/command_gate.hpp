// SPDX-License-Identifier: Apache-2.0
// What the end cap does with one Command_ sample, decided without DDS, clocks or
// the loop (pure, unit-tested). The rules, in order:
//
// 1. Not addressed to this end cap (endcap_mask): ignored, no ack.
// 2. A sample already answered (same writer, same seq): the first answer again,
//    nothing else (the ground tool re-sends until it hears an ack).
// 3. Another message-format version, or an unknown kind: refused (acked).
// 4. Emergency stop: delivered. It bypasses ordering and staleness (and, in the
//    node, the mailbox: it is a latched counter the loop reads every cycle).
// 5. Ordering, per writer: a seq older than the newest one this writer sent
//    (serial-number arithmetic, so the random 32-bit base may wrap) is a late or
//    replayed sample: refused as out_of_order, never acted on.
// 6. Start only: its wire times must be valid (wire_time.hpp) and, once the clock
//    is synchronized, it must not have been issued more than `max_age_ns` ago
//    (a start at a stale time would start in the wrong phase). Stop and clear-fault
//    are not judged by any clock: a peer that moves the end cap's clock must not be
//    able to make them "stale".
// 7. Clear-fault only: it names the emergency stops its sender had seen this end
//    cap take (its life id and count); when the end cap has taken another since, or
//    it is another life, the clear is refused (estop_unseen). Ordering (rule 5) is
//    per writer, so without this a clear-fault from one tool, delayed on the link,
//    could land after another tool's emergency stop and undo it. It also says when
//    the operator asked (host clock; bad_time if it is not a valid time): an end cap
//    that took an emergency stop issued after that refuses it too (estop_unseen), so
//    a tool that first heard this end cap after such a stop, and so names the count
//    with it, cannot undo it. Both times are the host's CLOCK_MONOTONIC, the clock
//    every ground tool on the host shares; an estop of another format version says
//    nothing of its time.
//
// History: the end cap's command reader is VOLATILE, so a fresh end cap is never
// handed the samples a writer kept from before it matched (msgs/qos_profiles.xml,
// fresh_commands); rules 2 and 5 are by sequence only.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/comms/wire/estop_count.hpp"
#include "firmware/comms/wire/reasons.hpp"

namespace tensegrity::fw::comms {

using WriterId = std::array<std::uint8_t, 16>;  // the DDS writer's GUID

enum class WireCommandKind : std::uint8_t { start = 0, stop = 1, emergency_stop = 2, clear_fault = 3 };

struct CommandSample {
  WriterId writer{};
  std::uint16_t format_version = 0;
  std::uint32_t seq = 0;
  std::uint8_t kind = 0;
  std::uint16_t endcap_mask = 0;
  std::int64_t start_host_time_ns = 0;
  std::int64_t issued_host_time_ns = 0;
  EstopCount estops_seen;               // this end cap's entries of Command_::lives_seen / estops_seen
  std::int64_t asked_host_time_ns = 0;  // clear-fault: when the operator asked (host clock)
};

enum class GateVerdict : std::uint8_t {
  not_addressed,  // no ack
  repeat,         // ack again with `reason`, do nothing
  refuse,         // ack with `reason`, do nothing
  deliver,        // act on it (start: map its time first), then ack
};

struct GateDecision {
  GateVerdict verdict = GateVerdict::not_addressed;
  CommandReason reason = CommandReason::accepted;
  WireCommandKind kind = WireCommandKind::stop;
};

// The host's clock as the end cap knows it, for rule 6.
struct HostClockView {
  bool synced = false;
  std::int64_t host_now_ns = 0;
};

class CommandGate {
 public:
  static constexpr std::size_t kRemembered = 64;  // answers kept for rule 2
  static constexpr std::size_t kWriters = 16;     // writers tracked for rule 5 (oldest forgotten)

  CommandGate(int endcap_id, std::uint16_t format_version, std::int64_t max_age_ns)
      : endcap_id_(endcap_id), format_version_(format_version), max_age_ns_(max_age_ns) {}

  // Rules 1-7; `estops_taken`: this end cap's own (rule 7). Does not change the
  // gate: call record() with the final answer.
  GateDecision judge(const CommandSample& c, const HostClockView& clock, const EstopCount& estops_taken) const;
  // Remembers the answer given to `c` (rule 2) and its seq as its writer's newest
  // (rule 5) when it was acted on or refused for what it said (not for ordering);
  // an emergency stop's issue time (rule 7).
  void record(const CommandSample& c, CommandReason reason);

 private:
  struct Answer {
    WriterId writer{};
    std::uint32_t seq = 0;
    CommandReason reason = CommandReason::accepted;
    bool used = false;
  };
  struct WriterState {
    WriterId writer{};
    std::uint32_t newest_seq = 0;
    std::uint64_t last_use = 0;
    bool used = false;
  };
  const Answer* find_answer(const CommandSample& c) const;
  const WriterState* find_writer(const WriterId& w) const;

  int endcap_id_;
  std::uint16_t format_version_;
  std::int64_t max_age_ns_;
  std::array<Answer, kRemembered> answers_{};
  std::size_t next_answer_ = 0;
  std::array<WriterState, kWriters> writers_{};
  std::uint64_t uses_ = 0;
  std::int64_t newest_estop_issued_ns_ = -1;  // host clock; -1: none with a known time
};

// Serial-number order of 32-bit sequence numbers (RFC 1982): a is newer than b.
constexpr bool seq_newer(std::uint32_t a, std::uint32_t b) {
  return a != b && static_cast<std::uint32_t>(a - b) < 0x8000'0000U;
}

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// Policy tables on the node thread (docs/design/dds.md "Policy upload"): received
// tables wait in an inbox and are judged one at a time; one that passes is stored
// with its identity as one durable record (app::PolicyStore) before it reaches the
// loop, and "accepted" is answered once the loop took it. Killed at any moment, the
// end cap reboots with the old record or the new one. No DDS: the node offers what
// its readers took and sends the answers given to `Answer`.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>

#include "firmware/app/host_link.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/comms/node/node_log.hpp"
#include "firmware/comms/wire/policy_wire.hpp"

namespace tensegrity::fw::comms {

using ActivePolicy = app::StoredIdentity;  // id empty: none known

class TableInbox {
 public:
  // Tables received but not yet judged; a table arriving when it is full is
  // answered loop_busy ("inbox full") at once and dropped: the uploader re-sends.
  static constexpr std::size_t kCapacity = 8;
  using Answer = std::function<void(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text)>;

  // `store` (may be null) keeps the active table and its identity across reboots;
  // its current() record is the active policy at start.
  TableInbox(const PolicyExpectations& expect, std::int64_t loop_ack_timeout_ns, app::PolicyStore* store, Answer answer,
             const NodeLog& log);

  // A table one of the node's participants took: queued, or dropped as a copy of
  // one queued (during a rejoin's overlap both participants may take it).
  void offer(const PolicyTableMsg& msg);
  // Follows the table in flight and judges the queued ones; `loop` is the loop's
  // latest telemetry, null before the loop published any.
  void poll(std::int64_t now_ns, const app::Telemetry* loop);

  // The control loop's thread: lock-free, no allocation.
  bool take(app::HostTable& out) noexcept { return tables_.pop(out); }

  const ActivePolicy& active() const { return active_; }
  // Handed to the loop and not answered yet: the loop takes it within a cycle or
  // two, so the node looks again soon.
  bool awaiting_loop() const { return in_flight_.active && !in_flight_.answered; }

 private:
  // The table on its way to the loop: stored, handed over, not yet echoed.
  struct InFlight {
    bool active = false;
    bool answered = false;  // loop_busy already sent (the loop was slow)
    PolicyTableMsg msg;
    app::StoredIdentity identity;
    core::EndcapTable table{};
    std::uint32_t loop_sequence = 0;
    std::int64_t since_ns = 0;
  };
  struct LastAnswer {
    bool valid = false;
    std::uint32_t upload_sequence = 0;
    std::uint64_t digest = 0;
    PolicyReason reason = PolicyReason::accepted;
    std::string text;
  };

  void judge(const PolicyTableMsg& msg, std::int64_t now_ns, const app::Telemetry* loop);
  void hand_over(const PolicyTableMsg& msg, const core::EndcapTable& table, std::int64_t now_ns,
                 const app::Telemetry* loop);
  void follow(std::int64_t now_ns, const app::Telemetry* loop);
  bool commit(const core::EndcapTable& table, const app::StoredIdentity& identity, std::string& error);
  void restore_active();
  void answer(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text);

  PolicyExpectations expect_;
  std::int64_t loop_ack_timeout_ns_;
  app::PolicyStore* store_;
  Answer answer_;
  const NodeLog& log_;
  app::SpscRing<app::HostTable, 4> tables_;  // to the loop
  std::deque<PolicyTableMsg> inbox_;         // at most kCapacity
  InFlight in_flight_;
  LastAnswer last_answer_;
  std::uint32_t loop_sequence_ = 0;
  ActivePolicy active_;
  core::EndcapTable active_table_{};  // what the store holds, to restore after a refusal
  bool have_active_table_ = false;
};

}  // namespace tensegrity::fw::comms

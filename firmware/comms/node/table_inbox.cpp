// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/table_inbox.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "core/table.hpp"

namespace tensegrity::fw::comms {

TableInbox::TableInbox(const PolicyExpectations& expect, std::int64_t loop_ack_timeout_ns, app::PolicyStore* store,
                       Answer answer, const NodeLog& log)
    : expect_(expect), loop_ack_timeout_ns_(loop_ack_timeout_ns), store_(store), answer_(std::move(answer)), log_(log) {
  app::StoredTable stored;
  if (store_ != nullptr && store_->current(stored)) {
    active_ = stored.identity;
    active_table_ = stored.table;
    have_active_table_ = true;
  }
}

// A table that reaches both participants is taken once here, or, if the first copy
// has left the inbox, judged as a retry and given the same answer.
void TableInbox::offer(const PolicyTableMsg& msg) {
  if (msg.target_endcap() != expect_.endcap_id) return;  // another end cap's table
  const bool queued = std::any_of(inbox_.begin(), inbox_.end(), [&](const PolicyTableMsg& q) {
    return q.upload_sequence() == msg.upload_sequence() && policy_digest(q) == policy_digest(msg);
  });
  if (queued) return;
  if (inbox_.size() >= kCapacity) {
    answer(msg, PolicyReason::loop_busy, "table inbox full: re-send later");
    return;
  }
  inbox_.push_back(msg);
}

void TableInbox::poll(std::int64_t now, const app::Telemetry* loop) {
  if (in_flight_.active) follow(now, loop);
  while (!inbox_.empty()) {
    if (awaiting_loop()) break;  // answered once the loop takes it
    const PolicyTableMsg incoming = inbox_.front();
    inbox_.pop_front();
    if (in_flight_.active) {
      // The loop has not taken the previous table yet (it was answered loop_busy):
      // one table in flight at a time, or stored and played could differ.
      const bool retry = incoming.upload_sequence() == in_flight_.msg.upload_sequence() &&
                         policy_digest(incoming) == policy_digest(in_flight_.msg);
      answer(incoming, PolicyReason::loop_busy,
             retry ? "control loop has not taken the table yet" : "previous table not taken by the loop yet");
      continue;
    }
    judge(incoming, now, loop);
  }
}

void TableInbox::judge(const PolicyTableMsg& incoming, std::int64_t now, const app::Telemetry* loop) {
  // A retry of the table just answered (its ack was lost or is late): the same
  // answer. A retry is the same sequence AND the same content; a different table
  // under a reused sequence is judged anew.
  if (last_answer_.valid && incoming.upload_sequence() == last_answer_.upload_sequence &&
      policy_digest(incoming) == last_answer_.digest) {
    answer(incoming, last_answer_.reason, last_answer_.text);
    return;
  }
  PolicyCheck check = check_policy(incoming, expect_);
  if (check.reason == PolicyReason::wrong_format_version) log_("REFUSED policy table: %s", check.text.c_str());
  if (check.reason != PolicyReason::accepted) {
    answer(incoming, check.reason, check.text);
    return;
  }
  if (!active_.policy_id.empty() && incoming.policy_id().to_string() == active_.policy_id &&
      incoming.policy_version() == active_.policy_version && incoming.checksum() == active_.checksum) {
    answer(incoming, PolicyReason::already_active, describe(PolicyReason::already_active));
    return;
  }
  if (!incoming.force() && !active_.policy_id.empty() && incoming.policy_version() <= active_.policy_version) {
    char text[160];
    std::snprintf(text, sizeof text, "version %u is not newer than active %s v%u (use force)",
                  incoming.policy_version(), active_.policy_id.c_str(), active_.policy_version);
    answer(incoming, PolicyReason::stale_version, text);
    return;
  }
  hand_over(incoming, check.table, now, loop);
}

bool TableInbox::commit(const core::EndcapTable& table, const app::StoredIdentity& identity, std::string& error) {
  if (store_ == nullptr) return true;  // nothing to keep across reboots
  return store_->save(table, identity, error) == StorageResult::ok;
}

// The store holds a table the loop did not take: put the running one back.
void TableInbox::restore_active() {
  std::string error;
  if (have_active_table_ && !commit(active_table_, active_, error)) {
    log_("cannot restore the previous table in storage: %s", error.c_str());
  }
}

// Durable first (table and identity, one record), then to the loop.
void TableInbox::hand_over(const PolicyTableMsg& msg, const core::EndcapTable& table, std::int64_t now,
                           const app::Telemetry* loop) {
  const app::StoredIdentity identity{msg.policy_id().to_string(), msg.policy_version(), msg.checksum()};
  std::string error;
  if (!commit(table, identity, error)) {
    answer(msg, PolicyReason::storage_failed, describe(PolicyReason::storage_failed) + (": " + error));
    return;
  }
  app::HostTable handover;
  handover.sequence = ++loop_sequence_;
  handover.table = table;
  if (!tables_.push(handover)) {
    restore_active();
    answer(msg, PolicyReason::loop_busy, "table mailbox to the control loop is full");
    return;
  }
  in_flight_ = InFlight{true, false, msg, identity, table, handover.sequence, now};
  follow(now, loop);
}

void TableInbox::follow(std::int64_t now, const app::Telemetry* loop) {
  if (loop != nullptr && loop->table_ack_sequence == in_flight_.loop_sequence) {
    in_flight_.active = false;
    if (loop->table_ack_error != core::TableError::none) {
      restore_active();
      answer(in_flight_.msg, from_table_error(loop->table_ack_error),
             std::string("control loop refused it: ") + core::describe(loop->table_ack_error));
      return;
    }
    active_ = in_flight_.identity;
    active_table_ = in_flight_.table;
    have_active_table_ = true;
    log_("policy %s v%u accepted%s", in_flight_.identity.policy_id.c_str(), in_flight_.identity.policy_version,
         in_flight_.answered ? " (taken late: it was answered loop_busy)" : "");
    answer(in_flight_.msg, PolicyReason::accepted, describe(PolicyReason::accepted));
  } else if (!in_flight_.answered && now - in_flight_.since_ns > loop_ack_timeout_ns_) {
    // Stored already; the loop may still take it, and then the identity follows
    // (above): the telemetry's active policy tells the rest.
    in_flight_.answered = true;
    answer(in_flight_.msg, PolicyReason::loop_busy, describe(PolicyReason::loop_busy));
  }
}

void TableInbox::answer(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text) {
  answer_(msg, reason, text);
  // Transient answers are not repeated to a retry: it is judged again.
  if (reason != PolicyReason::loop_busy && reason != PolicyReason::storage_failed) {
    last_answer_ = LastAnswer{true, msg.upload_sequence(), policy_digest(msg), reason, text};
  }
  if (!is_accepted(reason)) {
    log_("policy %s v%u rejected: %s", msg.policy_id().c_str(), msg.policy_version(), text.c_str());
  }
}

}  // namespace tensegrity::fw::comms

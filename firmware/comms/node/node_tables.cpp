// SPDX-License-Identifier: Apache-2.0
// Policy tables: judge, store (table + identity, one durable record), hand to the
// loop, acknowledge once the loop took it. docs/design/dds.md "Policy upload".
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "core/table.hpp"
#include "tensegrity_msgs/msg/PolicyAck.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

namespace {
// Seconds from a config to nanoseconds: the one rounding conversion, core's.
std::int64_t to_ns(double seconds) { return core::seconds_to_ns(seconds); }
}  // namespace

// During a rejoin's overlap (node_rejoin.cpp) the old participant may be the only
// one that hears the host: its tables count as much as the new one's. A table that
// reaches both is taken once here, or, if the first copy has left the inbox, judged
// as a retry and given the same answer.
void EndcapNode::take_tables(Dds& d) {
  PolicyTableMsg msg;
  dds::SampleInfo info;
  while (d.policy->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || msg.target_endcap() != config_.endcap_id) continue;  // another end cap's table
    const bool queued = std::any_of(inbox_.begin(), inbox_.end(), [&](const PolicyTableMsg& q) {
      return q.upload_sequence() == msg.upload_sequence() && policy_digest(q) == policy_digest(msg);
    });
    if (queued) continue;
    if (inbox_.size() >= kInboxCapacity) {
      send_policy_ack(msg, PolicyReason::loop_busy, "table inbox full: re-send later");
      continue;
    }
    inbox_.push_back(msg);
  }
}

void EndcapNode::handle_tables(std::int64_t now) {
  take_tables(*dds_);
  if (retiring_ != nullptr) take_tables(*retiring_);
  if (in_flight_.active) finish_in_flight(now);
  while (!inbox_.empty()) {
    const PolicyTableMsg incoming = inbox_.front();
    if (in_flight_.active && !in_flight_.answered) break;  // answered once the loop takes it
    inbox_.pop_front();
    if (in_flight_.active) {
      // The loop has not taken the previous table yet (it was answered loop_busy):
      // one table in flight at a time, or stored and played could differ.
      const bool retry = incoming.upload_sequence() == in_flight_.msg.upload_sequence() &&
                         policy_digest(incoming) == policy_digest(in_flight_.msg);
      send_policy_ack(incoming, PolicyReason::loop_busy,
                      retry ? "control loop has not taken the table yet" : "previous table not taken by the loop yet");
      continue;
    }
    judge_table(incoming, now);
  }
}

void EndcapNode::judge_table(const PolicyTableMsg& incoming, std::int64_t now) {
  // A retry of the table just answered (its ack was lost or is late): the same
  // answer. A retry is the same sequence AND the same content; a different table
  // under a reused sequence is judged anew.
  if (last_answer_.valid && incoming.upload_sequence() == last_answer_.upload_sequence &&
      policy_digest(incoming) == last_answer_.digest) {
    send_policy_ack(incoming, last_answer_.reason, last_answer_.text);
    return;
  }
  PolicyCheck check = check_policy(incoming, config_.expect);
  if (check.reason == PolicyReason::wrong_format_version) log("REFUSED policy table: %s", check.text.c_str());
  if (check.reason != PolicyReason::accepted) {
    send_policy_ack(incoming, check.reason, check.text);
    return;
  }
  const ActivePolicy active = active_policy();
  if (!active.policy_id.empty() && incoming.policy_id().to_string() == active.policy_id &&
      incoming.policy_version() == active.policy_version && incoming.checksum() == active.checksum) {
    send_policy_ack(incoming, PolicyReason::already_active, describe(PolicyReason::already_active));
    return;
  }
  if (!incoming.force() && !active.policy_id.empty() && incoming.policy_version() <= active.policy_version) {
    char text[160];
    std::snprintf(text, sizeof text, "version %u is not newer than active %s v%u (use force)",
                  incoming.policy_version(), active.policy_id.c_str(), active.policy_version);
    send_policy_ack(incoming, PolicyReason::stale_version, text);
    return;
  }
  hand_over(incoming, check.table, now);
}

bool EndcapNode::commit(const core::EndcapTable& table, const app::StoredIdentity& identity, std::string& error) {
  if (store_ == nullptr) return true;  // nothing to keep across reboots
  return store_->save(table, identity, error) == StorageResult::ok;
}

// Durable first (table and identity, one record), then to the loop: killed at any
// moment, the end cap reboots with the old record or the new one.
void EndcapNode::hand_over(const PolicyTableMsg& msg, const core::EndcapTable& table, std::int64_t now) {
  const app::StoredIdentity identity{msg.policy_id().to_string(), msg.policy_version(), msg.checksum()};
  std::string error;
  if (!commit(table, identity, error)) {
    send_policy_ack(msg, PolicyReason::storage_failed, describe(PolicyReason::storage_failed) + (": " + error));
    return;
  }
  app::HostTable handover;
  handover.sequence = ++loop_sequence_;
  handover.table = table;
  if (!tables_.push(handover)) {
    if (have_active_table_ && !commit(active_table_, active_policy(), error)) {
      log("cannot restore the previous table in storage: %s", error.c_str());
    }
    send_policy_ack(msg, PolicyReason::loop_busy, "table mailbox to the control loop is full");
    return;
  }
  in_flight_ = InFlight{true, false, msg, identity, table, handover.sequence, now};
  finish_in_flight(now);
}

void EndcapNode::finish_in_flight(std::int64_t now) {
  const app::Telemetry& t = last_telemetry_.telemetry;
  if (loop_seen_ && t.table_ack_sequence == in_flight_.loop_sequence) {
    in_flight_.active = false;
    if (t.table_ack_error != core::TableError::none) {
      // The store holds a table the loop refused: put the running one back.
      std::string error;
      if (have_active_table_ && !commit(active_table_, active_policy(), error)) {
        log("cannot restore the previous table in storage: %s", error.c_str());
      }
      send_policy_ack(in_flight_.msg, from_table_error(t.table_ack_error),
                      std::string("control loop refused it: ") + core::describe(t.table_ack_error));
      return;
    }
    {
      std::lock_guard lock(mutex_);
      active_ = in_flight_.identity;
    }
    active_table_ = in_flight_.table;
    have_active_table_ = true;
    log("policy %s v%u accepted%s", in_flight_.identity.policy_id.c_str(), in_flight_.identity.policy_version,
        in_flight_.answered ? " (taken late: it was answered loop_busy)" : "");
    send_policy_ack(in_flight_.msg, PolicyReason::accepted, describe(PolicyReason::accepted));
  } else if (!in_flight_.answered && now - in_flight_.since_ns > to_ns(config_.loop_ack_timeout_s)) {
    // Stored already; the loop may still take it, and then the identity follows
    // (above): the telemetry's active policy tells the rest.
    in_flight_.answered = true;
    send_policy_ack(in_flight_.msg, PolicyReason::loop_busy, describe(PolicyReason::loop_busy));
  }
}

void EndcapNode::send_policy_ack(const PolicyTableMsg& msg, PolicyReason reason, const std::string& text) {
  m::PolicyAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  ack.upload_sequence(msg.upload_sequence());
  ack.accepted(is_accepted(reason));
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(text.substr(0, 128));
  const ActivePolicy active = active_policy();
  ack.active_policy_id(active.policy_id);
  ack.active_policy_version(active.policy_version);
  ack.active_checksum(active.checksum);
  // On both participants during a rejoin's overlap: which one the host hears is not
  // known, and an uploader takes the first ack of a sequence and ignores the rest.
  dds_->policy_ack->write(&ack);
  if (retiring_ != nullptr) retiring_->policy_ack->write(&ack);
  // Transient answers are not repeated to a retry: it is judged again.
  if (reason != PolicyReason::loop_busy && reason != PolicyReason::storage_failed) {
    last_answer_ = LastAnswer{true, msg.upload_sequence(), policy_digest(msg), reason, text};
  }
  if (!is_accepted(reason)) {
    log("policy %s v%u rejected: %s", msg.policy_id().c_str(), msg.policy_version(), text.c_str());
  }
}

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/command_gate.hpp"

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {

const CommandGate::Answer* CommandGate::find_answer(const CommandSample& c) const {
  for (const Answer& a : answers_) {
    if (a.used && a.seq == c.seq && a.writer == c.writer) return &a;
  }
  return nullptr;
}

const CommandGate::WriterState* CommandGate::find_writer(const WriterId& w) const {
  for (const WriterState& s : writers_) {
    if (s.used && s.writer == w) return &s;
  }
  return nullptr;
}

GateDecision CommandGate::judge(const CommandSample& c, const HostClockView& clock,
                                const EstopCount& estops_taken) const {
  GateDecision d;
  if (endcap_id_ < 0 || endcap_id_ > 15 || (c.endcap_mask & (1U << endcap_id_)) == 0) return d;
  if (const Answer* a = find_answer(c)) {
    d.verdict = GateVerdict::repeat;
    d.reason = a->reason;
    return d;
  }
  // An emergency stop is taken from any format version: a stop is the one order that
  // is safe to act on whatever a newer or older tool meant by the rest of the sample,
  // and refusing it would leave the motors running on a version mismatch.
  if (c.kind == static_cast<std::uint8_t>(WireCommandKind::emergency_stop)) {
    d.verdict = GateVerdict::deliver;
    d.kind = WireCommandKind::emergency_stop;
    return d;
  }
  d.verdict = GateVerdict::refuse;
  if (c.format_version != format_version_) {
    d.reason = CommandReason::wrong_format_version;
    return d;
  }
  if (c.kind > static_cast<std::uint8_t>(WireCommandKind::clear_fault)) {
    d.reason = CommandReason::unknown_kind;
    return d;
  }
  d.kind = static_cast<WireCommandKind>(c.kind);
  if (const WriterState* w = find_writer(c.writer); w != nullptr && seq_newer(w->newest_seq, c.seq)) {
    d.reason = CommandReason::out_of_order;
    return d;
  }
  if (d.kind == WireCommandKind::start) {
    if (!valid_wire_time(c.start_host_time_ns) || !valid_wire_time(c.issued_host_time_ns)) {
      d.reason = CommandReason::bad_time;
      return d;
    }
    // Both valid wire times: the difference cannot overflow.
    if (clock.synced && valid_wire_time(clock.host_now_ns) && clock.host_now_ns - c.issued_host_time_ns > max_age_ns_) {
      d.reason = CommandReason::stale;
      return d;
    }
  }
  if (d.kind == WireCommandKind::clear_fault) {
    if (!valid_wire_time(c.asked_host_time_ns)) {
      d.reason = CommandReason::bad_time;
      return d;
    }
    if (c.estops_seen != estops_taken || newest_estop_issued_ns_ > c.asked_host_time_ns) {
      d.reason = CommandReason::estop_unseen;
      return d;
    }
  }
  d.verdict = GateVerdict::deliver;
  return d;
}

void CommandGate::record(const CommandSample& c, CommandReason reason) {
  const bool estop = c.kind == static_cast<std::uint8_t>(WireCommandKind::emergency_stop);
  if (estop && reason == CommandReason::accepted && c.format_version == format_version_ &&
      valid_wire_time(c.issued_host_time_ns) && c.issued_host_time_ns > newest_estop_issued_ns_) {
    newest_estop_issued_ns_ = c.issued_host_time_ns;
  }
  answers_[next_answer_] = Answer{c.writer, c.seq, reason, true};
  next_answer_ = (next_answer_ + 1) % kRemembered;
  if (reason == CommandReason::out_of_order) return;
  ++uses_;
  WriterState* slot = nullptr;
  for (WriterState& s : writers_) {
    if (s.used && s.writer == c.writer) {
      slot = &s;
      break;
    }
  }
  if (slot == nullptr) {
    slot = &writers_[0];  // a free slot, else the least recently used writer
    for (WriterState& s : writers_) {
      if (!s.used) {
        slot = &s;
        break;
      }
      if (s.last_use < slot->last_use) slot = &s;
    }
    *slot = WriterState{c.writer, c.seq, uses_, true};
    return;
  }
  if (seq_newer(c.seq, slot->newest_seq)) slot->newest_seq = c.seq;
  slot->last_use = uses_;
}

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// Commands, on Fast DDS's receive thread: the gate (command_gate.hpp) judges each
// sample, and what it delivers is acted on here at once. An emergency stop is a
// counter the loop reads every cycle: it waits for nothing (not for the node
// thread storing a table, not for room in a mailbox) and is acked as soon as it is
// latched. Every addressed command is acked, whatever the answer, on both participants
// during a rejoin's overlap.
#include <cstring>

#include "firmware/comms/logic/command_wire.hpp"
#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "firmware/comms/wire/wire_time.hpp"
#include "tensegrity_msgs/msg/Command.h"
#include "tensegrity_msgs/msg/CommandAck.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

namespace {

WriterId writer_of(const dds::SampleInfo& info) {
  WriterId w;
  const auto& guid = info.sample_identity.writer_guid();
  static_assert(sizeof(guid.guidPrefix.value) + sizeof(guid.entityId.value) == sizeof(WriterId));
  std::memcpy(w.data(), guid.guidPrefix.value, sizeof(guid.guidPrefix.value));
  std::memcpy(w.data() + sizeof(guid.guidPrefix.value), guid.entityId.value, sizeof(guid.entityId.value));
  return w;
}

const char* kind_name(std::uint8_t kind) {
  static const char* const names[] = {"start", "stop", "estop", "clear-fault"};
  return kind < 4 ? names[kind] : "unknown";
}

}  // namespace

void EndcapNode::on_commands(Dds& d) {
  std::lock_guard guard(d.callback_mutex);
  if (d.closed || d.command == nullptr) return;  // stopping, or still starting (taken next time)
  std::lock_guard serial(receive_mutex_);        // the other participant's listener, after a rejoin
  m::Command_ cmd;
  dds::SampleInfo info;
  while (d.command->take_next_sample(&cmd, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    const CommandSample c = to_sample(cmd, writer_of(info), config_.endcap_id);
    HostClockView clock;
    {
      std::lock_guard lock(mutex_);
      clock.synced = sync_.estimator().synced();
      const auto host_now = checked_add(clock_.now_ns(), sync_.estimator().best().offset_ns);
      clock.synced = clock.synced && host_now.has_value();
      clock.host_now_ns = host_now.value_or(0);
    }
    // Only this thread counts estops (act_on, under receive_mutex_): the count judged
    // is the one the clear would be applied after.
    const GateDecision decision = gate_.judge(c, clock, {life_id_, estops_.load(std::memory_order_acquire)});
    CommandReason reason = decision.reason;
    switch (decision.verdict) {
      case GateVerdict::not_addressed: continue;
      case GateVerdict::repeat: send_command_ack(d, c.seq, reason); continue;
      case GateVerdict::refuse: break;
      case GateVerdict::deliver: reason = act_on(c, decision.kind); break;
    }
    gate_.record(c, reason);
    send_command_ack(d, c.seq, reason);
    if (reason == CommandReason::wrong_format_version) {
      log("REFUSED command: format version %u, this end cap speaks %u", unsigned{c.format_version},
          unsigned{msgs::kFormatVersion});
    }
    log("command %u %s: %s", c.seq, kind_name(c.kind), describe(reason));
  }
}

CommandReason EndcapNode::act_on(const CommandSample& c, WireCommandKind kind) {
  if (kind == WireCommandKind::emergency_stop) {
    estops_.fetch_add(1, std::memory_order_acq_rel);
    return CommandReason::accepted;
  }
  app::HostCommand out;
  out.kind = static_cast<app::CommandKind>(kind);
  if (kind == WireCommandKind::start) {
    // The loop's latest cycle, not the node thread's last look at it.
    if (LoopPoint p; loop_in_.read(p)) {
      loop_point_ = p;
      loop_point_valid_ = true;
    }
    std::lock_guard lock(mutex_);
    if (!sync_.estimator().synced()) return CommandReason::clock_not_synced;
    if (!loop_point_valid_) return CommandReason::loop_not_running;
    // Said in the ack rather than found out by the loop a cycle later, unseen.
    if (const CommandReason ready = start_readiness(loop_point_.ready); ready != CommandReason::accepted) return ready;
    const auto start = start_mapper_.map(c.start_host_time_ns, sync_.estimator().best().offset_ns, loop_point_.clock);
    if (!start) return CommandReason::bad_time;
    out.start_time_ns = *start;
  }
  // Read after the estops before it were counted: the loop applies those first.
  out.estops_before = estops_.load(std::memory_order_acquire);
  return commands_.push(out) ? CommandReason::accepted : CommandReason::mailbox_full;
}

void EndcapNode::send_command_ack(Dds& d, std::uint32_t seq, CommandReason reason) {
  m::CommandAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  ack.seq(seq);
  ack.accepted(reason == CommandReason::accepted);
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(describe(reason));
  ack.life_id(life_id_);
  ack.estops_received(estops_.load(std::memory_order_acquire));
  d.command_ack->write(&ack);
  // During a rejoin's overlap the host may hear only the other participant (a muted old
  // one, or a new one not yet matched); the station takes the first ack of a sequence.
  if (d.peer != nullptr) d.peer->command_ack->write(&ack);
}

}  // namespace tensegrity::fw::comms

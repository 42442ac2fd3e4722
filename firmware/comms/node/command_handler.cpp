// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/command_handler.hpp"

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {

namespace {
const char* kind_name(std::uint8_t kind) {
  static const char* const names[] = {"start", "stop", "estop", "clear-fault"};
  return kind < 4 ? names[kind] : "unknown";
}
}  // namespace

CommandHandler::CommandHandler(int endcap_id, std::uint16_t format_version, std::int64_t max_age_ns,
                               std::int64_t start_grid_ns, std::uint32_t life_id, const NodeLog& log)
    : gate_(endcap_id, format_version, max_age_ns),
      start_mapper_(start_grid_ns),
      format_version_(format_version),
      life_id_(life_id),
      log_(log) {}

std::optional<CommandReason> CommandHandler::handle(const CommandSample& c, const SyncView& sync, std::int64_t now_ns) {
  const auto host_now = checked_add(now_ns, sync.offset_ns);
  const HostClockView clock{sync.synced && host_now.has_value(), host_now.value_or(0)};
  // Only this thread counts estops (act_on): the count judged is the one the clear
  // would be applied after.
  const GateDecision decision = gate_.judge(c, clock, {life_id_, estops()});
  CommandReason reason = decision.reason;
  switch (decision.verdict) {
    case GateVerdict::not_addressed: return std::nullopt;
    case GateVerdict::repeat: return reason;
    case GateVerdict::refuse: break;
    case GateVerdict::deliver: reason = act_on(c, decision.kind, sync); break;
  }
  gate_.record(c, reason);
  if (reason == CommandReason::wrong_format_version) {
    log_("REFUSED command: format version %u, this end cap speaks %u", unsigned{c.format_version},
         unsigned{format_version_});
  }
  log_("command %u %s: %s", c.seq, kind_name(c.kind), describe(reason));
  return reason;
}

CommandReason CommandHandler::act_on(const CommandSample& c, WireCommandKind kind, const SyncView& sync) {
  if (kind == WireCommandKind::emergency_stop) {
    estops_.fetch_add(1, std::memory_order_acq_rel);
    return CommandReason::accepted;
  }
  app::HostCommand out;
  out.kind = static_cast<app::CommandKind>(kind);
  if (kind == WireCommandKind::start) {
    if (const CommandReason mapped = map_start(c, sync, out); mapped != CommandReason::accepted) return mapped;
  }
  // Read after the estops before it were counted: the loop applies those first.
  out.estops_before = estops();
  return commands_.push(out) ? CommandReason::accepted : CommandReason::mailbox_full;
}

CommandReason CommandHandler::map_start(const CommandSample& c, const SyncView& sync, app::HostCommand& out) {
  // The loop's latest cycle, not the node thread's last look at it.
  if (LoopPoint p; loop_in_.read(p)) {
    loop_point_ = p;
    loop_point_valid_ = true;
  }
  if (!sync.synced) return CommandReason::clock_not_synced;
  if (!loop_point_valid_) return CommandReason::loop_not_running;
  if (const CommandReason ready = start_readiness(loop_point_.ready); ready != CommandReason::accepted) return ready;
  const auto start = start_mapper_.map(c.start_host_time_ns, sync.offset_ns, loop_point_.clock);
  if (!start) return CommandReason::bad_time;
  out.start_time_ns = *start;
  return CommandReason::accepted;
}

}  // namespace tensegrity::fw::comms

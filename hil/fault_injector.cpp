// SPDX-License-Identifier: Apache-2.0
#include "hil/fault_injector.hpp"

#include <cmath>

#include "hil/endcap_roster.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

int LiveFaultTarget::endcap_count() const { return roster_.size(); }

EndcapDevices& LiveFaultTarget::devices(int endcap) { return roster_.devices(endcap); }

void LiveFaultTarget::send(int endcap, const FrameOut& frames) {
  for (const CanFrame& f : frames) hub_.queue(endcap, f);
}

// A new program on the end cap's port may not read the hub's batched datagrams.
void LiveFaultTarget::kill(int endcap) {
  roster_.kill(endcap);
  hub_.forget_version(endcap);
}

void LiveFaultTarget::restart(int endcap) {
  hub_.forget_version(endcap);
  roster_.restart(endcap);
}

std::string LiveFaultTarget::freeze(int endcap, bool loop_only) { return roster_.freeze(endcap, loop_only); }

std::string LiveFaultTarget::set_dds_link(int endcap, bool up) { return roster_.processes().set_dds_link(endcap, up); }
std::string LiveFaultTarget::mute_dds(int endcap) { return roster_.processes().mute_dds(endcap); }
std::string LiveFaultTarget::operator_command(const ScenarioEvent& event) {
  return operator_ ? operator_(event) : FaultTarget::operator_command(event);
}

void FaultInjector::apply_due(std::int64_t step, std::int64_t now_ns, FaultTarget& target,
                              std::vector<std::string>& log) {
  const double now_s = static_cast<double>(step) * dt_s_;
  while (next_event_ < scenario_.events.size() && scenario_.events[next_event_].time_s <= now_s + 1e-9) {
    apply(scenario_.events[next_event_++], step, now_ns, target, log);
  }
  end_frame_faults(step, target);
}

void FaultInjector::apply(const ScenarioEvent& ev, std::int64_t step, std::int64_t now_ns, FaultTarget& target,
                          std::vector<std::string>& log) {
  const int e = ev.endcap;
  switch (ev.fault) {
    case FaultKind::cut_dds:
    case FaultKind::restore_dds:
    case FaultKind::mute_dds: log.push_back(apply_dds_link(ev, target)); return;
    case FaultKind::drive_fault:
    case FaultKind::drive_silent:
    case FaultKind::release_spool:
    case FaultKind::seize_spool: apply_to_motors(ev, now_ns, target); break;
    case FaultKind::load_cell_stuck: target.devices(e).set_load_cell_stuck(true); break;
    case FaultKind::load_cell_drift: target.devices(e).start_load_cell_drift(ev.params.n_per_s, now_ns); break;
    case FaultKind::drop_frames:
    case FaultKind::corrupt_frames: start_frame_fault(ev, step, target); break;
    case FaultKind::reboot_drive:
    case FaultKind::drive_preoperational: apply_to_motors(ev, now_ns, target); break;
    case FaultKind::load_cell_stopped:
      target.devices(e).load_cell().leave_operational(canopen::NmtState::stopped);
      break;
    case FaultKind::reboot_load_cell:
      target.devices(e).reboot_load_cell(now_ns, out_);
      target.send(e, out_);  // the boot-up, ahead of this tick's PDOs
      out_.clear();
      break;
    case FaultKind::hang_loop:
    case FaultKind::stop_endcap:
      if (const std::string why = target.freeze(e, ev.fault == FaultKind::hang_loop); !why.empty()) {
        log.push_back(ev.describe() + ": not done: " + why);
        return;
      }
      break;
    case FaultKind::estop:
    case FaultKind::clear_fault:
    case FaultKind::start:
      if (const std::string why = target.operator_command(ev); !why.empty()) {
        log.push_back(ev.describe() + ": not done: " + why);
        return;
      }
      break;
    case FaultKind::kill_endcap: target.kill(e); break;
    case FaultKind::restart_endcap: target.restart(e); break;
  }
  log.push_back(ev.describe());
}

void FaultInjector::apply_to_motors(const ScenarioEvent& ev, std::int64_t now_ns, FaultTarget& target) {
  EndcapDevices& devices = target.devices(ev.endcap);
  bool any = false;
  for (std::size_t m = 0; m < devices.motor_count(); ++m) {
    if (ev.params.motor >= 0 && static_cast<std::size_t>(ev.params.motor) != m) continue;
    any = true;
    switch (ev.fault) {
      case FaultKind::drive_fault: devices.fault_drive(m, ev.params.code, ev.params.release, now_ns, out_); break;
      case FaultKind::drive_silent: devices.silence_drive(m, true); break;
      case FaultKind::release_spool: devices.release_spool(m); break;
      case FaultKind::seize_spool: devices.seize_spool(m); break;
      case FaultKind::reboot_drive: devices.reboot_drive(m, now_ns, out_); break;
      case FaultKind::drive_preoperational:
        devices.drive(m).leave_operational(canopen::NmtState::pre_operational);
        break;
      default: break;
    }
  }
  if (!any) throw HilError(ev.describe() + ": end cap has no motor " + std::to_string(ev.params.motor));
  target.send(ev.endcap, out_);  // the EMCY, ahead of this tick's PDOs
  out_.clear();
}

void FaultInjector::start_frame_fault(const ScenarioEvent& ev, std::int64_t step, FaultTarget& target) {
  const bool corrupt = ev.fault == FaultKind::corrupt_frames;
  if (corrupt) {
    target.set_corrupt(ev.endcap, ev.params.probability, ev.params.corrupt_kind);
  } else {
    target.set_drop(ev.endcap, ev.params.probability);
  }
  // A duration past any run (1e15 steps) is "to the end": llround of a bigger value is undefined.
  const double steps = ev.params.duration_s / dt_s_;
  const std::int64_t until =
      ev.params.duration_s > 0.0 && steps < 1e15 ? step + static_cast<std::int64_t>(std::llround(steps)) : -1;
  frame_faults_.push_back({ev.endcap, corrupt, until});
}

void FaultInjector::end_frame_faults(std::int64_t step, FaultTarget& target) {
  for (auto it = frame_faults_.begin(); it != frame_faults_.end();) {
    if (it->until_step < 0 || step < it->until_step) {
      ++it;
      continue;
    }
    if (it->corrupt) {
      target.set_corrupt(it->endcap, 0.0, CorruptKind::frame);
    } else {
      target.set_drop(it->endcap, 0.0);
    }
    it = frame_faults_.erase(it);
  }
}

// endcap -1: every end cap, i.e. the host's own link.
std::string FaultInjector::apply_dds_link(const ScenarioEvent& ev, FaultTarget& target) {
  std::string skipped;
  for (int e = 0; e < target.endcap_count(); ++e) {
    if (ev.endcap >= 0 && e != ev.endcap) continue;
    const std::string why = ev.fault == FaultKind::mute_dds
                                ? target.mute_dds(e)
                                : target.set_dds_link(e, ev.fault == FaultKind::restore_dds);
    if (!why.empty()) skipped += (skipped.empty() ? "" : "; ") + ("end cap " + std::to_string(e) + ": " + why);
  }
  return ev.describe() + (skipped.empty() ? "" : ": not done for " + skipped);
}

}  // namespace tensegrity::hil

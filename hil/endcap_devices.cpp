// SPDX-License-Identifier: Apache-2.0
#include "hil/endcap_devices.hpp"

#include <stdexcept>

#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::hil {

using namespace fw::canopen;

EndcapDevices::EndcapDevices(int endcap, std::vector<int> cables, const fw::SpoolGeometry& spool,
                             double max_rest_length_m, bool lockstep)
    : endcap_(endcap), cables_(std::move(cables)), spool_(spool), max_rest_length_m_(max_rest_length_m) {
  if (cables_.size() > kDriveNodeIds.size()) throw std::invalid_argument("at most 4 motors per end cap");
  drives_.reserve(cables_.size());
  for (std::size_t m = 0; m < cables_.size(); ++m) {
    SimCia402Drive& d = drives_.emplace_back(kDriveNodeIds[m]);
    d.ideal_position = false;    // the position is the model's rest length
    d.tpdo_on_sync = !lockstep;  // lockstep: sensors go out before SYNC
    d.hold_enable = true;        // the start gate: enabled in phase by the stepper
    d.log_controlwords = false;
  }
  load_cell_.tpdo_on_sync = !lockstep;
}

void EndcapDevices::power_on(std::int64_t now_ns, FrameOut& out) {
  for (auto& d : drives_) d.boot(now_ns, out);
  load_cell_.boot(now_ns, out);
}

void EndcapDevices::on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) {
  for (std::size_t m = 0; m < drives_.size(); ++m) {
    if (frame.id == cob_id(Function::rpdo1, drives_[m].node_id()) && drives_[m].answering()) rpdo_seen_[m] = true;
    drives_[m].on_frame(frame, now_ns, out);
  }
  load_cell_.on_frame(frame, now_ns, out);
}

void EndcapDevices::tick(std::int64_t now_ns, FrameOut& out) {
  for (auto& d : drives_) d.tick(now_ns, out);
  load_cell_.tick(now_ns, out);
}

void EndcapDevices::update_from_model(std::span<const double> rest_length_m, std::span<const double> rate_m_per_s,
                                      std::span<const double> tension_n, std::int64_t now_ns) {
  std::array<double, 2> t{};
  for (std::size_t m = 0; m < drives_.size(); ++m) {
    const int c = cables_[m];
    drives_[m].set_actual(spool_.counts_from_rest_length(rest_length_m[c]),
                          spool_.counts_per_s_from_rate(rate_m_per_s[c]));
    if (m < 2) t[m] = tension_n[c];
  }
  load_cell_.set_tensions_n(t[0], t[1], now_ns);
}

void EndcapDevices::emit_sensors(FrameOut& out) {
  for (const auto& d : drives_) d.emit_tpdos(out);
  load_cell_.emit_tpdo(out);
}

bool EndcapDevices::all_rpdos() const {
  for (std::size_t m = 0; m < drives_.size(); ++m) {
    // A silent drive cannot take a frame; its end cap still sends RPDO1, so the
    // barrier waits for the master, not for the drive's ability to listen.
    if (!rpdo_seen_[m] && drives_[m].answering()) return false;
  }
  return true;
}

std::string EndcapDevices::missing_rpdo_nodes() const {
  std::string s;
  for (std::size_t m = 0; m < drives_.size(); ++m) {
    if (rpdo_seen_[m] || !drives_[m].answering()) continue;
    if (!s.empty()) s += ", ";
    s += std::to_string(drives_[m].node_id());
  }
  return s;
}

bool EndcapDevices::at_gate() const {
  for (const auto& d : drives_) {
    if (!d.at_enable_gate()) return false;
  }
  return !drives_.empty();
}

void EndcapDevices::release_gate() {
  for (auto& d : drives_) d.release_enable_gate();
}

bool EndcapDevices::any_follows() const {
  for (const auto& d : drives_) {
    if (d.follows_target()) return true;
  }
  return false;
}

void EndcapDevices::on_connection_lost() {
  for (auto& d : drives_) d.on_connection_lost();
}

void EndcapDevices::preferred(std::span<const double> rest_length_m, std::span<double> preferred_m) const {
  for (std::size_t m = 0; m < drives_.size(); ++m) {
    const int c = cables_[m];
    if (released_[m]) {
      preferred_m[c] = max_rest_length_m_;
    } else if (seized_[m]) {
      preferred_m[c] = rest_length_m[c];
    } else if (drives_[m].follows_target()) {
      preferred_m[c] = spool_.rest_length_from_counts(drives_[m].target_counts());
    } else {
      preferred_m[c] = rest_length_m[c];
    }
  }
}

void EndcapDevices::fault_drive(std::size_t motor, std::uint16_t code, bool release, std::int64_t now_ns,
                                FrameOut& out) {
  drives_.at(motor).inject_fault(code, now_ns, out);
  released_.at(motor) = release;
}

void EndcapDevices::silence_drive(std::size_t motor, bool silent) { drives_.at(motor).script.silent = silent; }

EndcapDeviceSummary EndcapDevices::summary() const {
  EndcapDeviceSummary s;
  for (const auto& d : drives_) {
    s.rpdos += d.rpdos_received();
    s.emcy_sent += d.emcy_sent();
    s.drive_states.push_back(to_string(d.state()));
    s.drive_period_ns.push_back(d.interpolation_period_ns());
  }
  s.load_cell_stuck = load_cell_.stuck();
  return s;
}

}  // namespace tensegrity::hil

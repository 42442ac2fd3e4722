// SPDX-License-Identifier: Apache-2.0
#include "tests/interop/cyclone/telemetry_stats.hpp"

#include <cstring>

namespace tensegrity::interop {
namespace {

// Cyclone's deserializer already enforces the IDL bounds (string<64> ends within
// its 65 bytes); what is left are the values the IDL cannot constrain.
std::string check_common(std::uint16_t format_version, std::int16_t endcap_id) {
  if (format_version != kFormatVersion) {
    return "format version " + std::to_string(format_version) + ", this peer speaks " + std::to_string(kFormatVersion);
  }
  if (endcap_id < 0 || endcap_id >= kEndcapCount) return "end cap id " + std::to_string(endcap_id) + " out of 0..11";
  return {};
}

}  // namespace

std::string check_telemetry(const TelemetryC& t) {
  std::string why = check_common(t.format_version, t.endcap_id);
  if (why.empty() && (t.motor_count < 1 || t.motor_count > 4)) {
    why = "motor count " + std::to_string(t.motor_count) + " out of 1..4";
  }
  return why;
}

std::string check_ack(const PolicyAckC& a) { return check_common(a.format_version, a.endcap_id); }

bool TelemetryStats::add(const TelemetryC& t, std::int64_t now_ns) {
  const std::string why = check_telemetry(t);
  if (!why.empty()) {
    ++refused_;
    last_refusal_ = why;
    return false;
  }
  EndcapTelemetry& e = endcaps_[static_cast<std::size_t>(t.endcap_id)];
  if (!e.seen) {
    e.seen = true;
    e.first_ns = now_ns;
  } else if (t.seq > e.last_seq + 1) {
    e.lost += t.seq - e.last_seq - 1;
  }
  e.last_seq = t.seq;
  ++e.samples;
  e.mode = t.mode;
  e.active_policy_id.assign(t.active_policy_id, strnlen(t.active_policy_id, sizeof t.active_policy_id));
  e.active_policy_version = t.active_policy_version;
  return true;
}

bool TelemetryStats::all_seen(std::uint16_t mask) const {
  for (int e = 0; e < kEndcapCount; ++e) {
    if ((mask & (1U << e)) != 0 && !endcaps_[static_cast<std::size_t>(e)].seen) return false;
  }
  return true;
}

}  // namespace tensegrity::interop

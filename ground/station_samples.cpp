// SPDX-License-Identifier: Apache-2.0
#include "ground/station_samples.hpp"

#include <algorithm>

#include "msgs/format_version.hpp"

namespace tensegrity::ground {

bool valid_endcap(int id) { return id >= 0 && id < kEndcapCount; }

bool merge_estops(EndcapStatus& e, const fw::comms::EstopCount& heard) {
  const auto& left = e.left_lives;
  if (heard.life_id != 0 && std::find(left.begin(), left.end(), heard.life_id) != left.end()) {
    ++e.stale_life_samples;
    return false;
  }
  if (heard.life_id != e.estops.life_id) {
    if (e.estops.life_id != 0) {
      std::copy_backward(e.left_lives.begin(), e.left_lives.end() - 1, e.left_lives.end());
      e.left_lives[0] = e.estops.life_id;
    }
    e.estops = heard;
  } else if (heard.count > e.estops.count) {
    e.estops.count = heard.count;
  }
  return true;
}

SampleVerdict take_heartbeat(EndcapStatus& e, const msg::Heartbeat_& hb, std::int64_t now_ns) {
  if (hb.format_version() != msgs::kFormatVersion) {
    ++e.refused;
    return SampleVerdict::wrong_format;
  }
  if (!merge_estops(e, {hb.life_id(), hb.estops_received()})) return SampleVerdict::stale_life;
  e.seen = true;
  e.heartbeat = hb;
  e.heartbeat_host_ns = now_ns;
  return SampleVerdict::taken;
}

SampleVerdict take_telemetry(EndcapStatus& e, const msg::Telemetry_& t, std::int64_t now_ns) {
  if (t.format_version() != msgs::kFormatVersion) {
    ++e.refused;
    return SampleVerdict::wrong_format;
  }
  if (e.have_telemetry && t.seq() > e.telemetry.seq() + 1) e.telemetry_gaps += t.seq() - e.telemetry.seq() - 1;
  e.have_telemetry = true;
  e.telemetry = t;
  e.telemetry_host_ns = now_ns;
  ++e.telemetry_count;
  return SampleVerdict::taken;
}

SampleVerdict check_ack(std::uint16_t format_version) {
  return format_version == msgs::kFormatVersion ? SampleVerdict::taken : SampleVerdict::wrong_format;
}

}  // namespace tensegrity::ground

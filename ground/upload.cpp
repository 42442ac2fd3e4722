// SPDX-License-Identifier: Apache-2.0
#include "ground/upload.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace tensegrity::ground {

std::vector<msg::PolicyTable_> policy_messages(const sim::Policy& policy, const sim::Robot& robot,
                                               const fw::comms::PolicyIdentity& identity,
                                               std::uint32_t first_sequence) {
  std::vector<msg::PolicyTable_> out;
  for (int e = 0; e < robot.endcap_count(); ++e) {
    out.push_back(fw::comms::make_policy_message(sim::endcap_table(policy, robot, e), e, identity,
                                                 first_sequence + static_cast<std::uint32_t>(e)));
  }
  return out;
}

std::uint32_t random_sequence_base() {
  std::random_device rd;
  return (static_cast<std::uint32_t>(rd()) & 0x7FFF'FF00U) + 256U;
}

bool UploadReport::all_accepted() const {
  return !results.empty() && std::all_of(results.begin(), results.end(), [](const auto& r) { return r.accepted; });
}

UploadReport upload(Station& station, const std::vector<msg::PolicyTable_>& tables, const UploadOptions& options) {
  if (!(options.timeout_s > 0.0) || !(options.retry_interval_s > 0.0)) {
    throw std::invalid_argument("upload: timeout and retry interval must be > 0 s");
  }
  UploadReport report;
  const std::int64_t start = Station::now_ns();
  const std::int64_t deadline = start + static_cast<std::int64_t>(options.timeout_s * 1e9);
  const auto retry_ns = static_cast<std::int64_t>(options.retry_interval_s * 1e9);
  station.take_policy_acks();  // anything older belongs to another upload
  for (const auto& t : tables) {
    EndcapUploadResult r;
    r.endcap = t.target_endcap();
    r.text = "no acknowledgement";
    report.results.push_back(r);
  }
  std::size_t outstanding = tables.size();
  std::int64_t next_send = start;
  while (outstanding > 0) {
    const std::int64_t now = Station::now_ns();
    if (now >= deadline) break;
    if (now >= next_send) {
      for (std::size_t i = 0; i < tables.size(); ++i) {
        if (report.results[i].acked) continue;
        station.write_policy(tables[i]);
        ++report.results[i].attempts;
      }
      next_send = now + retry_ns;
    }
    station.wait_for_policy_acks(std::min(next_send, deadline));
    const std::int64_t arrived = Station::now_ns();
    for (const auto& ack : station.take_policy_acks()) {
      for (std::size_t i = 0; i < tables.size(); ++i) {
        EndcapUploadResult& r = report.results[i];
        if (r.acked || ack.upload_sequence() != tables[i].upload_sequence() ||
            ack.endcap_id() != tables[i].target_endcap()) {
          continue;
        }
        r.acked = true;
        r.accepted = ack.accepted();
        r.reason = static_cast<fw::comms::PolicyReason>(ack.reason());
        r.text = ack.reason_text().to_string();
        r.active_policy_id = ack.active_policy_id().to_string();
        r.active_policy_version = ack.active_policy_version();
        r.latency_s = static_cast<double>(arrived - start) / 1e9;
        --outstanding;
      }
    }
  }
  report.total_s = static_cast<double>(Station::now_ns() - start) / 1e9;
  return report;
}

std::string format_upload_report(const UploadReport& report) {
  std::string out = "endcap  result    tries  latency_ms  active                     reason\n";
  char line[512];
  for (const auto& r : report.results) {
    const char* result = !r.acked ? "MISSING" : r.accepted ? "accepted" : "REJECTED";
    std::string active =
        r.active_policy_id.empty() ? "-" : r.active_policy_id + " v" + std::to_string(r.active_policy_version);
    std::snprintf(line, sizeof line, "%6d  %-8s  %5d  %10.1f  %-25s  %s\n", r.endcap, result, r.attempts,
                  r.acked ? r.latency_s * 1e3 : NAN, active.c_str(),
                  r.acked ? (std::string(fw::comms::to_string(r.reason)) + ": " + r.text).c_str() : r.text.c_str());
    out += line;
  }
  return out;
}

}  // namespace tensegrity::ground

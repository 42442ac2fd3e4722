// SPDX-License-Identifier: Apache-2.0
// Policy upload: one table per end cap, every end cap acknowledges, what is missing
// is sent again. The code path shared by `tensegrity upload` and the HIL launcher.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/comms/wire/policy_wire.hpp"
#include "ground/station.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"

namespace tensegrity::ground {

// One message per end cap of `robot`, each addressed to and checksummed for its
// end cap; upload sequences are `first_sequence + endcap`.
std::vector<msg::PolicyTable_> policy_messages(const sim::Policy& policy, const sim::Robot& robot,
                                               const fw::comms::PolicyIdentity& identity, std::uint32_t first_sequence);

// A fresh random base for upload and command sequence numbers: acks from an
// earlier run, kept in an end cap's transient-local history, must not match.
std::uint32_t random_sequence_base();

struct UploadOptions {
  double timeout_s = 10.0;
  double retry_interval_s = 1.0;  // re-send tables not yet acknowledged this often
};

struct EndcapUploadResult {
  int endcap = 0;
  bool acked = false;
  bool accepted = false;
  fw::comms::PolicyReason reason = fw::comms::PolicyReason::accepted;
  std::string text;  // the end cap's reason, or "no acknowledgement"
  std::string active_policy_id;
  std::uint32_t active_policy_version = 0;
  int attempts = 0;
  double latency_s = 0.0;  // first send to ack
};

struct UploadReport {
  std::vector<EndcapUploadResult> results;  // in end cap order
  double total_s = 0.0;
  bool all_accepted() const;
};

UploadReport upload(Station& station, const std::vector<msg::PolicyTable_>& tables, const UploadOptions& options);

// A fixed-width table, one line per end cap.
std::string format_upload_report(const UploadReport& report);

}  // namespace tensegrity::ground

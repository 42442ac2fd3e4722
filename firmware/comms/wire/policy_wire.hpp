// SPDX-License-Identifier: Apache-2.0
// PolicyTable_ <-> core::EndcapTable, the policy checksum, and the end cap's checks
// of a received table. Shared by the end cap's node and the ground uploader so both
// sides compute the checksum from the same code.
//
// Checksum: CRC-32 (firmware/hal/crc32.hpp) over this little-endian encoding:
//   "TPC1" | endcap_id i32 | policy_version u32 | motor_count u32 | complexity u32 |
//   period_s f64 | phase_offset_s f64 | value count u32 | values f64... |
//   policy_id length u32 | policy_id bytes | robot length u32 | robot bytes
// (f64 as its IEEE-754 bit pattern). Addressing (target_endcap, upload_sequence)
// and `force` are not covered: they are about delivery, not about the table.
#pragma once

#include <cstdint>
#include <string>

#include "firmware/comms/wire/reasons.hpp"
#include "core/limits.hpp"
#include "core/table.hpp"
#include "tensegrity_msgs/msg/PolicyTable.h"

namespace tensegrity::fw::comms {

using PolicyTableMsg = tensegrity_msgs::msg::dds_::PolicyTable_;

std::uint32_t policy_checksum(const PolicyTableMsg& msg);
// A 64-bit digest (FNV-1a) of everything a table message says: the checksummed
// fields, the checksum field itself, force and the addressing. A retry is the same
// upload_sequence AND the same digest; a different table under a reused sequence
// is judged anew.
std::uint64_t policy_digest(const PolicyTableMsg& msg);

struct PolicyIdentity {
  std::string policy_id;
  std::uint32_t policy_version = 0;
  std::string robot;
  bool force = false;
};

// A complete, checksummed message for end cap `endcap` (addressed to it).
PolicyTableMsg make_policy_message(const core::EndcapTable& table, int endcap, const PolicyIdentity& identity,
                                   std::uint32_t upload_sequence);

// Copies sizes and values; false (and `out` untouched) when the counts do not fit
// core::EndcapTable's bounds.
bool to_endcap_table(const PolicyTableMsg& msg, core::EndcapTable& out);

struct PolicyExpectations {
  int endcap_id = 0;
  std::uint32_t motor_count = 2;
  core::MotorLimits limits{};
  std::string robot;  // empty: any robot
};

struct PolicyCheck {
  PolicyReason reason = PolicyReason::accepted;
  std::string text;  // the reason with the numbers that caused it
  core::EndcapTable table{};
};

// Every check that does not depend on what is active (format, identity, sizes,
// checksum, values); the version check is the node's, it knows the active one.
PolicyCheck check_policy(const PolicyTableMsg& msg, const PolicyExpectations& expect);

}  // namespace tensegrity::fw::comms

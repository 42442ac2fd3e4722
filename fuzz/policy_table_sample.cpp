// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a PolicyTable_ sample off the wire into the end cap's checks
// (firmware/comms/wire/policy_wire). Oracle: a table the checks accept is one the core
// accepts too (core::validate) for the same motor count and limits.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "cdr_sample.hpp"
#include "firmware/comms/wire/policy_wire.hpp"
#include "core/table.hpp"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"

namespace comms = tensegrity::fw::comms;
namespace core = tensegrity::core;
namespace m = tensegrity_msgs::msg::dds_;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  m::PolicyTable_ msg;
  if (!tensegrity::fuzz::deserialize_sample<m::PolicyTable_PubSubType>(data, size, msg)) return 0;
  // Half the inputs get a correct checksum, so the search also reaches the checks
  // behind it (a mutated byte almost never keeps a CRC-32 right by itself).
  if (size % 2 == 0) msg.checksum(comms::policy_checksum(msg));
  comms::PolicyExpectations expect;
  expect.endcap_id = msg.target_endcap() >= 0 && msg.target_endcap() < 12 ? msg.target_endcap() : 0;
  expect.motor_count = 2;
  const comms::PolicyCheck check = comms::check_policy(msg, expect);
  if (check.reason == comms::PolicyReason::accepted &&
      core::validate(check.table, expect.motor_count, expect.limits) != core::TableError::none) {
    std::abort();
  }
  core::EndcapTable table;
  (void)comms::to_endcap_table(msg, table);
  return 0;
}

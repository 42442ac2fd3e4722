// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a Command_ sample off the wire, decoded as the end cap's reader
// decodes it.
#include <cstddef>
#include <cstdint>

#include "cdr_sample.hpp"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"

namespace m = tensegrity_msgs::msg::dds_;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  m::Command_ cmd;
  (void)tensegrity::fuzz::deserialize_sample<m::Command_PubSubType>(data, size, cmd);
  return 0;
}

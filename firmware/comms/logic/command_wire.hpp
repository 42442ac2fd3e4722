// SPDX-License-Identifier: Apache-2.0
// A Command_ sample as the command gate sees it: the fields the gate judges, and
// from the per-end-cap arrays only this end cap's entries (an id outside them names
// no emergency stops). Apart from the node, so that what the fuzzer feeds the gate
// is what the node feeds it.
#pragma once

#include "firmware/comms/logic/command_gate.hpp"
#include "tensegrity_msgs/msg/Command.h"

namespace tensegrity::fw::comms {

CommandSample to_sample(const tensegrity_msgs::msg::dds_::Command_& cmd, const WriterId& writer, int endcap_id);

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/nmt.hpp"

#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::fw::canopen {

const char* to_string(NmtCommand command) {
  switch (command) {
    case NmtCommand::start: return "start";
    case NmtCommand::stop: return "stop";
    case NmtCommand::enter_pre_operational: return "enter pre-operational";
    case NmtCommand::reset_node: return "reset node";
    case NmtCommand::reset_communication: return "reset communication";
  }
  return "unknown";
}

const char* to_string(NmtState state) {
  switch (state) {
    case NmtState::boot_up: return "boot-up";
    case NmtState::stopped: return "stopped";
    case NmtState::operational: return "operational";
    case NmtState::pre_operational: return "pre-operational";
    case NmtState::unknown: return "unknown";
  }
  return "invalid";
}

CanFrame encode_nmt(NmtCommand command, std::uint8_t node_id) {
  CanFrame f;
  f.id = cob_id(Function::nmt, 0);
  f.dlc = 2;
  f.data[0] = static_cast<std::uint8_t>(command);
  f.data[1] = node_id;
  return f;
}

bool decode_nmt(const CanFrame& frame, NmtCommand& command, std::uint8_t& node_id) {
  if (frame.id != 0 || frame.extended || frame.rtr || frame.dlc != 2 || frame.data[1] > kNodeIdMax) {
    return false;
  }
  switch (frame.data[0]) {
    case 0x01:
    case 0x02:
    case 0x80:
    case 0x81:
    case 0x82:
      command = static_cast<NmtCommand>(frame.data[0]);
      node_id = frame.data[1];
      return true;
    default: return false;
  }
}

CanFrame encode_heartbeat(std::uint8_t node_id, NmtState state) {
  CanFrame f;
  f.id = cob_id(Function::heartbeat, node_id);
  f.dlc = 1;
  f.data[0] = static_cast<std::uint8_t>(state);
  return f;
}

bool decode_nmt_state(std::uint8_t byte, NmtState& state) {
  switch (byte) {
    case 0x00:
    case 0x04:
    case 0x05:
    case 0x7F: state = static_cast<NmtState>(byte); return true;
    default: return false;
  }
}

}  // namespace tensegrity::fw::canopen

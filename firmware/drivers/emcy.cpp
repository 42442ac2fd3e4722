// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/emcy.hpp"

#include "firmware/drivers/byte_order.hpp"
#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::fw::canopen {

CanFrame encode_emcy(std::uint8_t node_id, const EmcyMessage& m) {
  CanFrame f;
  f.id = cob_id(Function::sync_or_emcy, node_id);
  f.dlc = 8;
  put_u16(&f.data[0], m.error_code);
  f.data[2] = m.error_register;
  for (std::size_t i = 0; i < m.manufacturer.size(); ++i) f.data[3 + i] = m.manufacturer[i];
  return f;
}

bool decode_emcy(const CanFrame& frame, EmcyMessage& m) {
  if (frame.extended || frame.rtr || frame.dlc != 8) return false;
  m.error_code = get_u16(&frame.data[0]);
  m.error_register = frame.data[2];
  for (std::size_t i = 0; i < m.manufacturer.size(); ++i) m.manufacturer[i] = frame.data[3 + i];
  return true;
}

const char* emcy_error_text(std::uint16_t code) {
  switch (code) {
    case 0x0000: return "error reset or no error";
    case 0x1000: return "generic error";
    case 0x2310: return "continuous over-current";
    case 0x2320: return "short circuit at outputs";
    case 0x3110: return "mains over-voltage";
    case 0x3120: return "mains under-voltage";
    case 0x3210: return "DC link over-voltage";
    case 0x3220: return "DC link under-voltage";
    case 0x4210: return "excess temperature device";
    case 0x4310: return "excess temperature drive";
    case 0x5530: return "data storage (EEPROM) error";
    case 0x6100: return "internal software error";
    case 0x7121: return "motor blocked";
    case 0x7305: return "incremental sensor 1 fault";
    case 0x8110: return "CAN overrun (objects lost)";
    case 0x8120: return "CAN in error passive mode";
    case 0x8130: return "life guard or heartbeat error";
    case 0x8140: return "recovered from bus off";
    case 0x8141: return "bus off occurred";
    case 0x8210: return "PDO not processed due to length error";
    case 0x8220: return "PDO length exceeded";
    case 0x8611: return "following error";
    case 0xFF00: return "device specific";
    default: break;
  }
  switch (code & 0xF000) {
    case 0x1000: return "generic error";
    case 0x2000: return "current";
    case 0x3000: return "voltage";
    case 0x4000: return "temperature";
    case 0x5000: return "device hardware";
    case 0x6000: return "device software";
    case 0x7000: return "additional modules";
    case 0x8000: return "monitoring";
    case 0x9000: return "external error";
    case 0xF000: return "additional functions";
    default: break;
  }
  return "unknown error code";
}

}  // namespace tensegrity::fw::canopen

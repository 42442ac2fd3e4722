// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen::sdo_abort {

const char* text(std::uint32_t code) {
  switch (code) {
    case kToggleBit: return "toggle bit not alternated";
    case kTimeout: return "SDO protocol timed out";
    case kBadCommand: return "client/server command specifier not valid or unknown";
    case 0x0504'0002: return "invalid block size";
    case 0x0504'0003: return "invalid sequence number";
    case 0x0504'0004: return "CRC error";
    case kOutOfMemory: return "out of memory";
    case kUnsupportedAccess: return "unsupported access to an object";
    case kWriteOnly: return "attempt to read a write-only object";
    case kReadOnly: return "attempt to write a read-only object";
    case kNoObject: return "object does not exist in the object dictionary";
    case kNotMappable: return "object cannot be mapped to the PDO";
    case kPdoTooLong: return "number and length of mapped objects would exceed PDO length";
    case kIncompatible: return "general parameter incompatibility";
    case 0x0604'0047: return "general internal incompatibility in the device";
    case kHardwareError: return "access failed due to a hardware error";
    case kLengthMismatch: return "data type does not match, length of service parameter does not match";
    case kLengthTooHigh: return "data type does not match, length of service parameter too high";
    case kLengthTooLow: return "data type does not match, length of service parameter too low";
    case kNoSubindex: return "sub-index does not exist";
    case 0x0609'0030: return "invalid value for parameter (download only)";
    case kValueTooHigh: return "value of parameter written too high (download only)";
    case kValueTooLow: return "value of parameter written too low (download only)";
    case 0x0609'0036: return "maximum value is less than minimum value";
    case 0x060A'0023: return "resource not available: SDO connection";
    case kGeneral: return "general error";
    case kCannotStore: return "data cannot be transferred or stored to the application";
    case kCannotStoreLocal: return "data cannot be transferred or stored because of local control";
    case kCannotStoreState: return "data cannot be transferred or stored in the present device state";
    case 0x0800'0023: return "object dictionary dynamic generation failed or no object dictionary present";
    case kNoData: return "no data available";
  }
  return "unknown SDO abort code";
}

}  // namespace tensegrity::fw::canopen::sdo_abort

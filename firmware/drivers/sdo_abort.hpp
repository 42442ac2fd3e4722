// SPDX-License-Identifier: Apache-2.0
// SDO abort codes (CiA 301 table 22), for logs and fault reports.
#pragma once

#include <cstdint>

namespace tensegrity::fw::canopen::sdo_abort {

inline constexpr std::uint32_t kToggleBit = 0x0503'0000;
inline constexpr std::uint32_t kTimeout = 0x0504'0000;
inline constexpr std::uint32_t kBadCommand = 0x0504'0001;
inline constexpr std::uint32_t kOutOfMemory = 0x0504'0005;
inline constexpr std::uint32_t kUnsupportedAccess = 0x0601'0000;
inline constexpr std::uint32_t kWriteOnly = 0x0601'0001;
inline constexpr std::uint32_t kReadOnly = 0x0601'0002;
inline constexpr std::uint32_t kNoObject = 0x0602'0000;
inline constexpr std::uint32_t kNotMappable = 0x0604'0041;
inline constexpr std::uint32_t kPdoTooLong = 0x0604'0042;
inline constexpr std::uint32_t kIncompatible = 0x0604'0043;
inline constexpr std::uint32_t kHardwareError = 0x0606'0000;
inline constexpr std::uint32_t kLengthMismatch = 0x0607'0010;
inline constexpr std::uint32_t kLengthTooHigh = 0x0607'0012;
inline constexpr std::uint32_t kLengthTooLow = 0x0607'0013;
inline constexpr std::uint32_t kNoSubindex = 0x0609'0011;
inline constexpr std::uint32_t kValueRange = 0x0609'0030;
inline constexpr std::uint32_t kValueTooHigh = 0x0609'0031;
inline constexpr std::uint32_t kValueTooLow = 0x0609'0032;
inline constexpr std::uint32_t kGeneral = 0x0800'0000;
inline constexpr std::uint32_t kCannotStore = 0x0800'0020;
inline constexpr std::uint32_t kCannotStoreLocal = 0x0800'0021;
inline constexpr std::uint32_t kCannotStoreState = 0x0800'0022;
inline constexpr std::uint32_t kNoData = 0x0800'0024;

// Never null; "unknown SDO abort code" for codes outside the table.
const char* text(std::uint32_t code);

}  // namespace tensegrity::fw::canopen::sdo_abort

// SPDX-License-Identifier: Apache-2.0
// CRC-32 (IEEE 802.3, reflected, poly 0xEDB88320; same values as zlib's crc32).
// Written here rather than taken from zlib so the firmware's cross build (armhf,
// aarch64) needs no extra target library for twenty lines of code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tensegrity::fw {

// Pass the previous result as `crc` to continue over several buffers.
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

}  // namespace tensegrity::fw

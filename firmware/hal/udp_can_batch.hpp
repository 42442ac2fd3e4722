// SPDX-License-Identifier: Apache-2.0
// CAN frames over UDP, version 2: several frames in one datagram, so that what an
// end cap or the HIL emulator puts on the bus in one control cycle costs one
// system call and one wake-up of the receiver instead of one per frame.
//
//   offset      size field
//   0           4    magic "TCAN"
//   4           1    version, 2
//   5           1    count N, 1..64
//   6           2    reserved, zero
//   8 + 16 i    16   record i (i = 0..N-1), in bus order:
//     +0        1    flags, as version 1 (bit0 extended, bit1 RTR, bit2 error report)
//     +1        1    dlc, 0..8
//     +2        2    reserved, zero
//     +4        4    can_id u32, little-endian
//     +8        8    data; bytes past dlc zero when sent, ignored when read
//
// The datagram is exactly 8 + 16 N bytes (at most 1032: one Ethernet frame). A bad
// header drops the whole datagram; a bad record drops that record only, as a bad
// frame on a CAN bus would. Version 1 (udp_can_wire.hpp) stays valid: a receiver
// reads both (DatagramReader), a sender uses version 2 only when told its peer
// reads it. Full description: docs/design/udp-can.md. Pure code, no OS headers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/hal/can_frame.hpp"
#include "firmware/hal/udp_can_wire.hpp"

namespace tensegrity::fw::udp_can {

inline constexpr std::uint8_t kBatchVersion = 2;
inline constexpr std::size_t kBatchHeaderBytes = 8;
inline constexpr std::size_t kBatchRecordBytes = 16;
inline constexpr std::size_t kMaxBatchFrames = 64;
inline constexpr std::size_t kMaxDatagramBytes = kBatchHeaderBytes + kMaxBatchFrames * kBatchRecordBytes;

// One version-2 datagram, built in place (no allocation).
class BatchWriter {
 public:
  BatchWriter() { clear(); }
  // False when the batch is full: send it and clear() first. Like encode(), the
  // caller checks is_valid(frame); an invalid frame is written as given.
  bool add(const CanFrame& frame);
  bool add_error_report(std::uint32_t error_class, const std::array<std::uint8_t, 8>& detail);
  std::size_t count() const { return count_; }
  bool empty() const { return count_ == 0; }
  bool full() const { return count_ == kMaxBatchFrames; }
  // The datagram to send: header and count() records.
  std::span<const std::uint8_t> bytes() const {
    return {bytes_.data(), kBatchHeaderBytes + count_ * kBatchRecordBytes};
  }
  void clear();

 private:
  bool add_record(std::uint8_t flags, std::uint8_t dlc, std::uint8_t data_bytes, std::uint32_t id,
                  const std::array<std::uint8_t, 8>& data);
  std::array<std::uint8_t, kMaxDatagramBytes> bytes_{};
  std::size_t count_ = 0;
};

// Reads one received datagram of either version without copying it.
class DatagramReader {
 public:
  explicit DatagramReader(std::span<const std::uint8_t> datagram);
  // Decoded::frame when the datagram as a whole is sound (its records are then
  // read one by one); otherwise the reason all of it is dropped.
  Decoded status() const { return status_; }
  std::uint8_t version() const { return version_; }
  std::size_t count() const { return count_; }  // 0 unless status() is frame
  // Record i < count(): frame, error_report, or why this record is dropped.
  Decoded read(std::size_t i, CanFrame& frame) const;

 private:
  std::span<const std::uint8_t> datagram_;
  Decoded status_ = Decoded::bad_size;
  std::uint8_t version_ = 0;
  std::size_t count_ = 0;
};

}  // namespace tensegrity::fw::udp_can

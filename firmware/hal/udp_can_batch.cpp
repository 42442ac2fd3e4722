// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/udp_can_batch.hpp"

namespace tensegrity::fw::udp_can {
namespace {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'C', 'A', 'N'};

bool magic_ok(std::span<const std::uint8_t> d) {
  for (std::size_t i = 0; i < kMagic.size(); ++i) {
    if (d[i] != kMagic[i]) return false;
  }
  return true;
}

}  // namespace

void BatchWriter::clear() {
  for (std::size_t i = 0; i < kMagic.size(); ++i) bytes_[i] = kMagic[i];
  bytes_[4] = kBatchVersion;
  bytes_[5] = 0;
  bytes_[6] = 0;
  bytes_[7] = 0;
  count_ = 0;
}

bool BatchWriter::add_record(std::uint8_t flags, std::uint8_t dlc, std::uint8_t data_bytes, std::uint32_t id,
                             const std::array<std::uint8_t, 8>& data) {
  if (full()) return false;
  std::uint8_t* r = &bytes_[kBatchHeaderBytes + count_ * kBatchRecordBytes];
  r[0] = flags;
  r[1] = dlc;
  r[2] = 0;
  r[3] = 0;
  for (std::size_t i = 0; i < 4; ++i) r[4 + i] = static_cast<std::uint8_t>(id >> (8 * i));
  // Every byte of the record is written: the buffer is reused without clearing.
  for (std::size_t i = 0; i < 8; ++i) r[8 + i] = i < data_bytes && i < 8 ? data[i] : 0;
  ++count_;
  bytes_[5] = static_cast<std::uint8_t>(count_);
  return true;
}

bool BatchWriter::add(const CanFrame& frame) {
  std::uint8_t flags = 0;
  if (frame.extended) flags |= kFlagExtended;
  if (frame.rtr) flags |= kFlagRtr;
  // An RTR frame carries no data bytes, whatever dlc it requests (as version 1).
  return add_record(flags, frame.dlc, frame.rtr ? 0 : frame.dlc, frame.id, frame.data);
}

bool BatchWriter::add_error_report(std::uint32_t error_class, const std::array<std::uint8_t, 8>& detail) {
  return add_record(kFlagError, kCanMaxDlc, kCanMaxDlc, error_class, detail);
}

DatagramReader::DatagramReader(std::span<const std::uint8_t> datagram) : datagram_(datagram) {
  // The shortest datagram of either version is version 2's header.
  if (datagram.size() < kBatchHeaderBytes) return;  // bad_size
  if (!magic_ok(datagram)) {
    status_ = Decoded::bad_magic;
    return;
  }
  version_ = datagram[4];
  if (version_ == kVersion) {
    if (datagram.size() != kDatagramBytes) return;
    count_ = 1;
    status_ = Decoded::frame;
    return;
  }
  if (version_ != kBatchVersion) {
    status_ = Decoded::bad_version;
    return;
  }
  const std::size_t n = datagram[5];
  // A count of 0 or above the maximum, or one the length does not match, is a
  // truncated or padded datagram: its size is wrong.
  if (n == 0 || n > kMaxBatchFrames || datagram.size() != kBatchHeaderBytes + n * kBatchRecordBytes) return;
  if (datagram[6] != 0 || datagram[7] != 0) {
    status_ = Decoded::bad_reserved;
    return;
  }
  count_ = n;
  status_ = Decoded::frame;
}

Decoded DatagramReader::read(std::size_t i, CanFrame& frame) const {
  if (i >= count_) return status_ == Decoded::frame ? Decoded::bad_size : status_;
  if (version_ == kVersion) return decode(datagram_, frame);
  const std::uint8_t* r = &datagram_[kBatchHeaderBytes + i * kBatchRecordBytes];
  return detail::decode_fields(r[0], r[1], r[2] == 0 && r[3] == 0, detail::read_u32(&r[4]), &r[8], frame);
}

}  // namespace tensegrity::fw::udp_can

// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/udp_can_wire.hpp"

namespace tensegrity::fw::udp_can {
namespace {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'C', 'A', 'N'};

Datagram encode_raw(std::uint8_t flags, std::uint8_t dlc, std::uint32_t id, const std::array<std::uint8_t, 8>& data) {
  Datagram d{};
  for (std::size_t i = 0; i < kMagic.size(); ++i) d[i] = kMagic[i];
  d[4] = kVersion;
  d[5] = flags;
  d[6] = dlc;
  d[7] = 0;
  for (std::size_t i = 0; i < 4; ++i) d[8 + i] = static_cast<std::uint8_t>(id >> (8 * i));
  for (std::size_t i = 0; i < 8 && i < dlc; ++i) d[12 + i] = data[i];
  return d;
}

}  // namespace

const char* to_string(Decoded d) {
  switch (d) {
    case Decoded::frame: return "frame";
    case Decoded::error_report: return "error report";
    case Decoded::bad_size: return "wrong datagram size";
    case Decoded::bad_magic: return "wrong magic";
    case Decoded::bad_version: return "unsupported version";
    case Decoded::bad_flags: return "unknown flag bits";
    case Decoded::bad_reserved: return "reserved byte not zero";
    case Decoded::bad_dlc: return "dlc > 8";
    case Decoded::bad_id: return "id out of range";
  }
  return "unknown";
}

Datagram encode(const CanFrame& frame) {
  std::uint8_t flags = 0;
  if (frame.extended) flags |= kFlagExtended;
  if (frame.rtr) flags |= kFlagRtr;
  // An RTR frame carries no data bytes, whatever dlc it requests.
  const std::uint8_t data_bytes = frame.rtr ? 0 : frame.dlc;
  Datagram d = encode_raw(flags, data_bytes, frame.id, frame.data);
  d[6] = frame.dlc;
  return d;
}

Datagram encode_error_report(std::uint32_t error_class, const std::array<std::uint8_t, 8>& detail) {
  return encode_raw(kFlagError, kCanMaxDlc, error_class, detail);
}

Decoded decode(std::span<const std::uint8_t> datagram, CanFrame& frame) {
  if (datagram.size() != kDatagramBytes) return Decoded::bad_size;
  for (std::size_t i = 0; i < kMagic.size(); ++i) {
    if (datagram[i] != kMagic[i]) return Decoded::bad_magic;
  }
  if (datagram[4] != kVersion) return Decoded::bad_version;
  return detail::decode_fields(datagram[5], datagram[6], datagram[7] == 0, detail::read_u32(&datagram[8]),
                               &datagram[12], frame);
}

namespace detail {

std::uint32_t read_u32(const std::uint8_t* bytes) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(bytes[i]) << (8 * i);
  return v;
}

Decoded decode_fields(std::uint8_t flags, std::uint8_t dlc, bool reserved_zero, std::uint32_t id,
                      const std::uint8_t* data, CanFrame& frame) {
  if ((flags & ~(kFlagExtended | kFlagRtr | kFlagError)) != 0) return Decoded::bad_flags;
  const bool error = (flags & kFlagError) != 0;
  if (error && (flags & (kFlagExtended | kFlagRtr)) != 0) return Decoded::bad_flags;
  if (!reserved_zero) return Decoded::bad_reserved;
  if (dlc > kCanMaxDlc) return Decoded::bad_dlc;

  CanFrame f;
  f.id = id;
  f.extended = (flags & kFlagExtended) != 0;
  f.rtr = (flags & kFlagRtr) != 0;
  f.dlc = dlc;
  const std::uint8_t data_bytes = f.rtr ? 0 : dlc;
  for (std::size_t i = 0; i < data_bytes; ++i) f.data[i] = data[i];
  if (!error && !is_valid(f)) return Decoded::bad_id;
  if (error && id > kCanExtendedIdMax) return Decoded::bad_id;
  frame = f;
  return error ? Decoded::error_report : Decoded::frame;
}

}  // namespace detail

}  // namespace tensegrity::fw::udp_can

// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/sdo_codec.hpp"

#include "firmware/drivers/byte_order.hpp"
#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::fw::canopen {
namespace {

// Command byte: bits 7-5 command specifier, 3-2 n (4 - size), 1 e (expedited), 0 s (size set).
constexpr std::uint8_t kCcsDownload = 1;
constexpr std::uint8_t kCcsUpload = 2;
constexpr std::uint8_t kScsUpload = 2;
constexpr std::uint8_t kScsDownload = 3;
constexpr std::uint8_t kCsAbort = 4;

std::uint8_t expedited_byte(std::uint8_t cs, std::uint8_t size) {
  if (size < 1 || size > 4) return static_cast<std::uint8_t>(cs << 5 | 0x02);  // e=1, s=0
  return static_cast<std::uint8_t>(cs << 5 | (4 - size) << 2 | 0x03);
}

}  // namespace

CanFrame encode_sdo(std::uint8_t node_id, const SdoMessage& m) {
  const bool to_server = m.kind == SdoKind::download_request || m.kind == SdoKind::upload_request;
  CanFrame f;
  f.id = cob_id(to_server ? Function::sdo_rx : Function::sdo_tx, node_id);
  f.dlc = 8;
  put_u16(&f.data[1], m.address.index);
  f.data[3] = m.address.subindex;
  std::uint32_t payload = 0;
  switch (m.kind) {
    case SdoKind::download_request:
      f.data[0] = expedited_byte(kCcsDownload, m.size);
      payload = m.value;
      break;
    case SdoKind::download_response: f.data[0] = kScsDownload << 5; break;
    case SdoKind::upload_request: f.data[0] = kCcsUpload << 5; break;
    case SdoKind::upload_response:
      f.data[0] = expedited_byte(kScsUpload, m.size);
      payload = m.value;
      break;
    case SdoKind::abort:
      f.data[0] = kCsAbort << 5;
      payload = m.value;
      break;
    case SdoKind::unsupported: break;
  }
  // Bytes past `size` are "undefined" in CiA 301; zero keeps frames comparable.
  if (m.size >= 1 && m.size < 4) payload &= (1U << (8 * m.size)) - 1U;
  put_u32(&f.data[4], payload);
  return f;
}

bool decode_sdo(const CanFrame& frame, bool from_server, SdoMessage& m) {
  if (frame.extended || frame.rtr || frame.dlc != 8) return false;
  const Function expected = from_server ? Function::sdo_tx : Function::sdo_rx;
  if (function_of(frame.id) != expected) return false;
  const std::uint8_t cmd = frame.data[0];
  const std::uint8_t cs = cmd >> 5;
  SdoMessage out;
  out.address = {get_u16(&frame.data[1]), frame.data[3]};
  out.value = get_u32(&frame.data[4]);
  const bool expedited = (cmd & 0x02) != 0;
  const bool size_set = (cmd & 0x01) != 0;
  const auto size = static_cast<std::uint8_t>(size_set ? 4 - ((cmd >> 2) & 0x03) : 0);
  if (cs == kCsAbort) {
    out.kind = SdoKind::abort;
    out.size = 4;  // the abort code
  } else if (from_server && cs == kScsUpload && expedited) {
    out.kind = SdoKind::upload_response;
    out.size = size;
  } else if (from_server && cs == kScsDownload) {
    out.kind = SdoKind::download_response;
  } else if (!from_server && cs == kCcsDownload && expedited) {
    out.kind = SdoKind::download_request;
    out.size = size;
  } else if (!from_server && cs == kCcsUpload) {
    out.kind = SdoKind::upload_request;
  } else {
    out.kind = SdoKind::unsupported;
  }
  if (out.size >= 1 && out.size < 4) out.value &= (1U << (8 * out.size)) - 1U;
  m = out;
  return true;
}

}  // namespace tensegrity::fw::canopen

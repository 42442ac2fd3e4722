// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/sdo_client.hpp"

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {

const char* to_string(SdoStatus status) {
  switch (status) {
    case SdoStatus::idle: return "idle";
    case SdoStatus::pending: return "pending";
    case SdoStatus::done: return "done";
    case SdoStatus::aborted: return "aborted";
    case SdoStatus::timed_out: return "timed out";
  }
  return "unknown";
}

bool SdoClient::start_upload(SdoAddress address, std::int64_t now_ns, CanFrame& request) {
  if (busy()) return false;
  transfer_ = SdoTransfer{};
  transfer_.status = SdoStatus::pending;
  transfer_.upload = true;
  transfer_.address = address;
  transfer_.started_ns = now_ns;
  request = encode_sdo(node_id_, {SdoKind::upload_request, address, 0, 0});
  return true;
}

bool SdoClient::start_download(SdoAddress address, std::uint32_t value, std::uint8_t size_bytes, std::int64_t now_ns,
                               CanFrame& request) {
  if (busy() || size_bytes < 1 || size_bytes > 4) return false;
  transfer_ = SdoTransfer{};
  transfer_.status = SdoStatus::pending;
  transfer_.address = address;
  transfer_.value = value;
  transfer_.size = size_bytes;
  transfer_.started_ns = now_ns;
  request = encode_sdo(node_id_, {SdoKind::download_request, address, value, size_bytes});
  return true;
}

void SdoClient::finish_with_abort(std::uint32_t code, bool by_server, std::int64_t now_ns) {
  transfer_.status = SdoStatus::aborted;
  transfer_.abort_code = code;
  transfer_.aborted_by_server = by_server;
  transfer_.finished_ns = now_ns;
}

SdoRx SdoClient::on_response(const CanFrame& frame, std::int64_t now_ns, CanFrame& abort, bool& send_abort) {
  send_abort = false;
  SdoMessage m;
  if (!decode_sdo(frame, true, m)) return SdoRx::malformed;
  if (!busy() || m.address != transfer_.address) return SdoRx::unexpected;
  switch (m.kind) {
    case SdoKind::abort: finish_with_abort(m.value, true, now_ns); return SdoRx::completed;
    case SdoKind::upload_response:
      if (!transfer_.upload) break;
      transfer_.status = SdoStatus::done;
      transfer_.value = m.value;
      transfer_.size = m.size == 0 ? 4 : m.size;
      transfer_.finished_ns = now_ns;
      return SdoRx::completed;
    case SdoKind::download_response:
      if (transfer_.upload) break;
      transfer_.status = SdoStatus::done;
      transfer_.finished_ns = now_ns;
      return SdoRx::completed;
    default: break;
  }
  // A segmented upload start, or a response that does not fit the request: the
  // server now waits on us, so end the transfer on its side too.
  finish_with_abort(sdo_abort::kBadCommand, false, now_ns);
  abort = encode_sdo(node_id_, {SdoKind::abort, transfer_.address, sdo_abort::kBadCommand, 4});
  abort.id = cob_id(Function::sdo_rx, node_id_);  // from us, the client
  send_abort = true;
  return SdoRx::malformed;
}

bool SdoClient::poll(std::int64_t now_ns, CanFrame& abort) {
  if (!busy() || now_ns - transfer_.started_ns < timeout_ns_) return false;
  transfer_.status = SdoStatus::timed_out;
  transfer_.abort_code = sdo_abort::kTimeout;
  transfer_.finished_ns = now_ns;
  abort = encode_sdo(node_id_, {SdoKind::abort, transfer_.address, sdo_abort::kTimeout, 4});
  abort.id = cob_id(Function::sdo_rx, node_id_);  // from us, the client
  return true;
}

}  // namespace tensegrity::fw::canopen

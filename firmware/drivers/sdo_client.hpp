// SPDX-License-Identifier: Apache-2.0
// One SDO client channel to one server node: one expedited transfer at a time,
// with a timeout. It builds the frames; the caller sends them, so it needs no bus
// and can be driven entirely from tests.
#pragma once

#include <cstdint>

#include "firmware/drivers/sdo_codec.hpp"
#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::canopen {

enum class SdoStatus : std::uint8_t {
  idle,
  pending,
  done,       // value/size hold the uploaded data (uploads)
  aborted,    // abort_code says why (from the server, or ours on a bad reply)
  timed_out,  // no reply in time; an abort (0x05040000) was sent to the server
};

const char* to_string(SdoStatus status);

struct SdoTransfer {
  SdoStatus status = SdoStatus::idle;
  bool upload = false;
  SdoAddress address;
  std::uint32_t value = 0;
  std::uint8_t size = 0;
  std::uint32_t abort_code = 0;
  bool aborted_by_server = false;
  std::int64_t started_ns = 0;
  std::int64_t finished_ns = 0;
};

enum class SdoRx : std::uint8_t {
  completed,   // the pending transfer finished (done or aborted)
  unexpected,  // an SDO response with nothing pending, or for another object
  malformed,   // wrong length, or a response we cannot handle (answered by an abort)
};

class SdoClient {
 public:
  SdoClient(std::uint8_t node_id, std::int64_t timeout_ns) : node_id_(node_id), timeout_ns_(timeout_ns) {}

  // False (and no request) while a transfer is pending.
  bool start_upload(SdoAddress address, std::int64_t now_ns, CanFrame& request);
  // size_bytes 1..4.
  bool start_download(SdoAddress address, std::uint32_t value, std::uint8_t size_bytes, std::int64_t now_ns,
                      CanFrame& request);

  // A frame on 0x580 + node_id. When `send_abort` comes back true, `abort` must
  // be sent to tell the server we gave up.
  SdoRx on_response(const CanFrame& frame, std::int64_t now_ns, CanFrame& abort, bool& send_abort);
  // True when the pending transfer has just timed out; send `abort`.
  bool poll(std::int64_t now_ns, CanFrame& abort);

  const SdoTransfer& transfer() const { return transfer_; }
  bool busy() const { return transfer_.status == SdoStatus::pending; }
  // Back to idle once the caller has taken the result.
  void acknowledge() {
    if (!busy()) transfer_ = SdoTransfer{};
  }
  std::uint8_t node_id() const { return node_id_; }

 private:
  void finish_with_abort(std::uint32_t code, bool by_server, std::int64_t now_ns);

  std::uint8_t node_id_;
  std::int64_t timeout_ns_;
  SdoTransfer transfer_;
};

}  // namespace tensegrity::fw::canopen

// SPDX-License-Identifier: Apache-2.0
#include "hil/devices/sim_node.hpp"

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::hil {

using namespace fw::canopen;

void SimNode::boot(std::int64_t now_ns, FrameOut& out) {
  powered_ = true;
  nmt_ = NmtState::pre_operational;
  if (!script.silent) out.push_back(encode_heartbeat(node_id_, NmtState::boot_up));
  next_heartbeat_ns_ = now_ns + script.heartbeat_period_ns;
}

void SimNode::tick(std::int64_t now_ns, FrameOut& out) {
  if (!answering() || !script.heartbeat || now_ns < next_heartbeat_ns_) return;
  out.push_back(encode_heartbeat(node_id_, nmt_));
  next_heartbeat_ns_ = now_ns + script.heartbeat_period_ns;
}

void SimNode::on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) {
  if (!answering() || frame.extended || frame.rtr) return;
  NmtCommand command{};
  std::uint8_t target = 0;
  if (decode_nmt(frame, command, target)) {
    if (target != 0 && target != node_id_) return;
    switch (command) {
      case NmtCommand::start: nmt_ = NmtState::operational; break;
      case NmtCommand::stop: nmt_ = NmtState::stopped; break;
      case NmtCommand::enter_pre_operational: nmt_ = NmtState::pre_operational; break;
      case NmtCommand::reset_node:
        on_reset_node();
        boot(now_ns, out);
        break;
      case NmtCommand::reset_communication: boot(now_ns, out); break;
    }
    return;
  }
  if (frame.id == cob_id(Function::sdo_rx, node_id_)) {
    // SDO works in pre-operational and operational, not when stopped.
    if (nmt_ != NmtState::stopped) on_sdo_request(frame, out);
    return;
  }
  if (nmt_ == NmtState::operational) on_pdo_or_sync(frame, now_ns, out);
}

void SimNode::on_sdo_request(const CanFrame& frame, FrameOut& out) {
  SdoMessage request;
  if (!decode_sdo(frame, false, request)) return;
  if (request.kind == SdoKind::abort) return;  // the client gave up; nothing to answer
  ++sdo_requests;
  if (script.sdo_silent) return;
  SdoMessage reply{SdoKind::abort, request.address, 0, 4};
  if (script.sdo_abort_all != 0) {
    reply.value = script.sdo_abort_all;
  } else if (request.kind == SdoKind::upload_request) {
    std::uint32_t value = 0;
    std::uint8_t size = 0;
    const std::uint32_t abort = od_read(request.address, value, size);
    if (abort != 0) {
      reply.value = abort;
    } else if (script.sdo_segmented_upload) {
      CanFrame segmented = encode_sdo(node_id_, {SdoKind::upload_response, request.address, 100, 4});
      segmented.data[0] = 0x41;  // scs 2, e 0, s 1: 100 bytes follow in segments
      out.push_back(segmented);
      return;
    } else {
      reply = {SdoKind::upload_response, request.address, value, size};
    }
  } else if (request.kind == SdoKind::download_request) {
    const std::uint32_t abort = od_write(request.address, request.value, request.size);
    reply = abort != 0 ? SdoMessage{SdoKind::abort, request.address, abort, 4}
                       : SdoMessage{SdoKind::download_response, request.address, 0, 0};
  } else {
    reply.value = sdo_abort::kBadCommand;
  }
  out.push_back(encode_sdo(node_id_, reply));
}

}  // namespace tensegrity::hil

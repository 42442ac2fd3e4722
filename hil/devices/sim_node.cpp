// SPDX-License-Identifier: Apache-2.0
#include "hil/devices/sim_node.hpp"

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::hil {

using namespace fw::canopen;

void SimNode::boot(std::int64_t now_ns, FrameOut& out) {
  powered_ = true;
  nmt_ = NmtState::pre_operational;
  consumer_node_ = 0;
  consumer_time_ms_ = 0;
  consumer_armed_ = false;
  // 0x1017 too is a communication object: a reset brings back the factory default.
  heartbeat_period_ns_ = script.heartbeat_period_ns;
  if (!script.silent) out.push_back(encode_heartbeat(node_id_, NmtState::boot_up));
  next_heartbeat_ns_ = now_ns + heartbeat_period_ns_;
}

void SimNode::reboot(std::int64_t now_ns, FrameOut& out) {
  ++reboots_;
  on_reset_node();
  boot(now_ns, out);
}

void SimNode::tick(std::int64_t now_ns, FrameOut& out) {
  if (consumer_restart_) {
    consumer_restart_ = false;
    last_consumed_ns_ = now_ns;
  }
  if (powered_ && consumer_armed_ && now_ns - last_consumed_ns_ > std::int64_t{consumer_time_ms_} * 1'000'000) {
    consumer_armed_ = false;  // until the producer is heard again
    heartbeat_lost_ns_ = now_ns;
    ++heartbeat_losses_;
    on_heartbeat_lost(now_ns, out);
  }
  if (!answering() || !script.heartbeat || heartbeat_period_ns_ <= 0 || now_ns < next_heartbeat_ns_) return;
  out.push_back(encode_heartbeat(node_id_, nmt_));
  next_heartbeat_ns_ = now_ns + heartbeat_period_ns_;
}

void SimNode::leave_operational(NmtState state) {
  if (powered_ && nmt_ == NmtState::operational) nmt_ = state;
}

bool SimNode::consume_heartbeat(const CanFrame& frame, std::int64_t now_ns) {
  if (frame.id != cob_id(Function::heartbeat, consumer_node_) || consumer_node_ == 0 || frame.dlc != 1) return false;
  if (consumer_time_ms_ != 0) {
    consumer_armed_ = true;
    last_consumed_ns_ = now_ns;
  }
  return true;
}

void SimNode::on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) {
  if (!answering() || frame.extended || frame.rtr) return;
  if (consume_heartbeat(frame, now_ns)) return;
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
    std::uint32_t abort = 0;
    if (!comm_od_read(request.address, value, size, abort)) abort = od_read(request.address, value, size);
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
    std::uint32_t abort = 0;
    if (!comm_od_write(request.address, request.value, request.size, abort)) {
      abort = od_write(request.address, request.value, request.size);
    }
    reply = abort != 0 ? SdoMessage{SdoKind::abort, request.address, abort, 4}
                       : SdoMessage{SdoKind::download_response, request.address, 0, 0};
  } else {
    reply.value = sdo_abort::kBadCommand;
  }
  out.push_back(encode_sdo(node_id_, reply));
}

bool SimNode::comm_od_read(SdoAddress a, std::uint32_t& value, std::uint8_t& size, std::uint32_t& abort) {
  if (a.index == kOdConsumerHeartbeatTime) {
    abort = 0;
    if (a.subindex == 0) {
      value = 1;  // one consumer entry
      size = 1;
    } else if (a.subindex == 1) {
      value = consumer_heartbeat_entry(consumer_node_, consumer_time_ms_);
      size = 4;
    } else {
      abort = sdo_abort::kNoSubindex;
    }
    return true;
  }
  if (a.index == kOdProducerHeartbeatTime) {
    abort = a.subindex != 0 ? sdo_abort::kNoSubindex : 0;
    value = static_cast<std::uint32_t>(heartbeat_period_ns_ / 1'000'000);
    size = 2;
    return true;
  }
  return false;
}

bool SimNode::comm_od_write(SdoAddress a, std::uint32_t value, std::uint8_t size, std::uint32_t& abort) {
  if (a.index == kOdConsumerHeartbeatTime) {
    if (a.subindex == 0) {
      abort = sdo_abort::kReadOnly;
    } else if (a.subindex != 1) {
      abort = sdo_abort::kNoSubindex;
    } else if (size != 4) {
      abort = sdo_abort::kLengthMismatch;
    } else if ((value >> 24) != 0) {
      abort = sdo_abort::kValueRange;
    } else {
      abort = 0;
      consumer_node_ = static_cast<std::uint8_t>(value >> 16);
      consumer_time_ms_ = static_cast<std::uint16_t>(value & 0xFFFFU);
      consumer_armed_ = false;  // starts with the next heartbeat heard
    }
    return true;
  }
  if (a.index == kOdProducerHeartbeatTime) {
    if (a.subindex != 0) {
      abort = sdo_abort::kNoSubindex;
    } else if (size != 2) {
      abort = sdo_abort::kLengthMismatch;
    } else {
      abort = 0;
      heartbeat_period_ns_ = std::int64_t{value & 0xFFFFU} * 1'000'000;
      next_heartbeat_ns_ = 0;  // the new period runs from the next tick, not the old schedule
    }
    return true;
  }
  return false;
}

}  // namespace tensegrity::hil

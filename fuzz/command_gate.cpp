// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a run of Command_ samples into one end cap, each decoded as
// the node decodes it (generated deserialize, then command_wire's to_sample) and
// judged by the command gate, which remembers across the run as it does in the
// node. Input: endcap id, clock flags, host time, life id; then per sample one
// byte naming the writer (of 4, so ordering and repeats meet), a 16-bit length and
// that many bytes of serialized payload.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "cdr_sample.hpp"
#include "fuzz_input.hpp"
#include "firmware/comms/logic/command_gate.hpp"
#include "firmware/comms/logic/command_wire.hpp"
#include "msgs/format_version.hpp"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"

namespace comms = tensegrity::fw::comms;
namespace m = tensegrity_msgs::msg::dds_;

namespace {

using tensegrity::fuzz::Input;

bool addressed(const comms::CommandSample& c, int endcap_id) { return (c.endcap_mask & (1U << endcap_id)) != 0; }

// What the gate lets through is what the node may act on.
// An emergency stop addressed here is acted on unless it is one already answered.
void check(const comms::CommandSample& c, const comms::GateDecision& d, int endcap_id) {
  const bool estop = c.kind == static_cast<std::uint8_t>(comms::WireCommandKind::emergency_stop);
  if (!addressed(c, endcap_id) && d.verdict != comms::GateVerdict::not_addressed) std::abort();
  if (addressed(c, endcap_id) && estop && d.verdict != comms::GateVerdict::deliver &&
      d.verdict != comms::GateVerdict::repeat) {
    std::abort();
  }
  if (d.verdict == comms::GateVerdict::deliver && !estop) {
    if (c.format_version != tensegrity::msgs::kFormatVersion || c.kind > 3) std::abort();
    if (d.kind != static_cast<comms::WireCommandKind>(c.kind)) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Input in{data, size};
  const int endcap_id = in.take<std::uint8_t>() % 12;
  const auto flags = in.take<std::uint8_t>();
  comms::HostClockView clock{(flags & 1U) != 0, in.take<std::int64_t>()};
  comms::EstopCount taken{in.take<std::uint32_t>(), 0};
  comms::CommandGate gate(endcap_id, tensegrity::msgs::kFormatVersion, 2'000'000'000);
  std::array<comms::WriterId, 4> writers{};
  for (std::size_t w = 0; w < writers.size(); ++w) writers[w][15] = static_cast<std::uint8_t>(w + 1);
  while (in.left > 0) {
    const std::size_t writer = in.take<std::uint8_t>() % writers.size();
    const std::size_t length = in.take<std::uint16_t>() % 512;
    const std::size_t n = length < in.left ? length : in.left;
    m::Command_ cmd;
    const bool decoded = tensegrity::fuzz::deserialize_sample<m::Command_PubSubType>(in.at, n, cmd);
    in.at += n;
    in.left -= n;
    if (!decoded) continue;
    const comms::CommandSample c = comms::to_sample(cmd, writers[writer], endcap_id);
    const comms::GateDecision d = gate.judge(c, clock, taken);
    check(c, d, endcap_id);
    comms::CommandReason reason = d.reason;
    switch (d.verdict) {
      case comms::GateVerdict::not_addressed:
      case comms::GateVerdict::repeat: continue;
      case comms::GateVerdict::refuse: break;
      case comms::GateVerdict::deliver:
        reason = comms::CommandReason::accepted;
        if (d.kind == comms::WireCommandKind::emergency_stop) ++taken.count;
        break;
    }
    gate.record(c, reason);
  }
  return 0;
}

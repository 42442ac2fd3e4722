// SPDX-License-Identifier: Apache-2.0
// The message-format version every message carries first, in a header of its own
// (no DDS vendor's headers) so that a peer built on another DDS (the Cyclone DDS
// interop peer, tests/interop/cyclone) speaks the same one instead of a copy.
#pragma once

#include <cstdint>

namespace tensegrity::msgs {

// A peer with another value is refused (and logged), never decoded as if it were
// ours. Bump on any change to an IDL file.
// 2: time-sync request and reply carry a nonce.
// 3: a host's heartbeat names the end caps it hears (heard_endcaps).
// 4: a clear-fault names the emergency stops it has seen (estops_seen); heartbeats
//    and command acks carry the end cap's count (estops_received).
// 5: and the end cap's life (lives_seen; life_id).
// 6: a clear-fault says when the operator asked (asked_host_time_ns).
inline constexpr std::uint16_t kFormatVersion = 6;

}  // namespace tensegrity::msgs

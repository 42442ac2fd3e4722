// SPDX-License-Identifier: Apache-2.0
// A UDP transport that can be cut: while the flag it watches is set, every RTPS
// datagram this participant would send is discarded and every one it receives is
// dropped before Fast DDS sees it (or, muted, only the ones it sends). Both
// directions, so the participant experiences
// what a lost Wi-Fi link does to it (no heartbeats, no acks, no data, in or out),
// with nothing changed outside the process: this kernel has no netem, and filtering
// in the transport keeps the fault local to the one end cap it is injected into.
#pragma once

#include <atomic>
#include <memory>

#include <fastdds/rtps/transport/TransportDescriptorInterface.h>

namespace tensegrity::msgs {

// Wraps `low_level` (the profile's UDPv4 descriptor). While *cut is true nothing
// goes out or comes in; while *mute is true nothing goes out, and what comes in is
// delivered: one direction lost, as a security handshake stalled one way leaves a
// participant (docs/guide/security.md). Either may be null (never). Each must outlive the
// participant; it is read on every datagram (relaxed atomic load: a fault takes
// effect within one datagram, no ordering with other data is needed). Setting one
// from a signal handler is fine (lock-free atomic<bool>).
std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> make_link_cut_transport(
    std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> low_level, const std::atomic<bool>* cut,
    const std::atomic<bool>* mute = nullptr);

}  // namespace tensegrity::msgs

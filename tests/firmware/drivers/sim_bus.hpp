// SPDX-License-Identifier: Apache-2.0
// An in-memory CanBus with scripted devices behind it, for tests of code that
// owns a bus the way the end-cap application does (it calls send/receive itself).
// A frame sent is handed to every connected device at once; their answers wait in
// a fixed ring until receive() takes them, as on a real bus between cycles.
// After warm-up nothing here allocates, provided the devices' own logs have
// capacity (SimCia402Drive::controlwords: reserve it), so the code under test can
// be checked for allocations with the devices in the same thread.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/hal/can_bus.hpp"
#include "firmware/hal/clock.hpp"
#include "hil/devices/cia402_drive.hpp"
#include "hil/devices/load_cell.hpp"

namespace tensegrity::fw::sim {

// The emulated devices live in hil/devices (shared with the HIL emulator).
using hil::FrameOut;
using hil::SimCia402Drive;
using hil::SimLoadCell;
using hil::SimNode;

class SimCanBus final : public CanBus {
 public:
  explicit SimCanBus(const Clock& clock, std::size_t rx_capacity = 4096) : clock_(clock), ring_(rx_capacity) {
    out_.reserve(64);
  }

  void attach(SimNode& node) { nodes_.push_back({&node, true}); }
  // An unplugged device neither hears nor says anything (a cut cable).
  void set_connected(const SimNode& node, bool connected) {
    for (Entry& e : nodes_) {
      if (e.node == &node) e.connected = connected;
    }
  }

  void power_on() {
    for (Entry& e : nodes_) {
      if (e.connected) e.node->boot(clock_.now_ns(), out_);
    }
    queue_answers();
  }
  // Heartbeats and other time-driven output of the devices, once per cycle.
  void tick() {
    for (Entry& e : nodes_) {
      if (e.connected) e.node->tick(clock_.now_ns(), out_);
    }
    queue_answers();
  }
  // A frame from a third party (the HIL's SYNC): heard by the devices and by us.
  void inject(const CanFrame& frame) {
    deliver(frame);
    push(frame);
    queue_answers();
  }
  // A frame only the code under test receives (a device's EMCY, a forged frame).
  void inject_to_receiver(const CanFrame& frame) { push(frame); }

  CanResult send(const CanFrame& frame) override {
    if (!is_valid(frame)) {
      ++counters_.tx_dropped;
      return CanResult::invalid_frame;
    }
    ++counters_.tx_frames;
    if (frame.id == 0x080 && frame.dlc <= 1) ++syncs_sent;
    deliver(frame);
    queue_answers();
    return CanResult::ok;
  }
  CanResult receive(CanFrame& frame, std::int64_t) override {
    if (size_ == 0) return CanResult::timeout;
    frame = ring_[head_];
    head_ = (head_ + 1) % ring_.size();
    --size_;
    ++counters_.rx_frames;
    return CanResult::ok;
  }
  // Frames were delivered at send(): only counted, so tests see the loop flush.
  CanResult flush() override {
    ++flushes;
    return CanResult::ok;
  }
  CanCounters counters() const override { return counters_; }

  std::size_t pending() const { return size_; }
  std::uint64_t flushes = 0;
  std::uint64_t ring_overflows = 0;
  std::uint64_t syncs_sent = 0;

 private:
  struct Entry {
    SimNode* node;
    bool connected;
  };
  void deliver(const CanFrame& frame) {
    for (Entry& e : nodes_) {
      if (e.connected) e.node->on_frame(frame, clock_.now_ns(), out_);
    }
  }
  // The devices' answers into the receive ring.
  void queue_answers() {
    for (const CanFrame& f : out_) push(f);
    out_.clear();
  }
  void push(const CanFrame& frame) {
    if (size_ == ring_.size()) {
      ++ring_overflows;
      return;
    }
    ring_[(head_ + size_) % ring_.size()] = frame;
    ++size_;
  }

  const Clock& clock_;
  std::vector<Entry> nodes_;
  std::vector<CanFrame> ring_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  FrameOut out_;
  CanCounters counters_;
};

}  // namespace tensegrity::fw::sim

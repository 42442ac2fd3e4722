// SPDX-License-Identifier: Apache-2.0
// A master, a scripted drive and a load cell on one in-memory bus, stepped by a
// ManualClock: fully deterministic, no sockets, no sleeping.
#pragma once

#include <functional>
#include <vector>

#include "firmware/drivers/canopen_master.hpp"
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

// Records what the master sends; the bench delivers it.
class RecordingBus final : public CanBus {
 public:
  CanResult send(const CanFrame& frame) override {
    if (!is_valid(frame)) return CanResult::invalid_frame;
    pending.push_back(frame);
    log.push_back(frame);
    ++counters_.tx_frames;
    return CanResult::ok;
  }
  CanResult receive(CanFrame&, std::int64_t) override { return CanResult::timeout; }
  CanCounters counters() const override { return counters_; }

  std::vector<CanFrame> pending;
  std::vector<CanFrame> log;  // everything the master ever sent

 private:
  CanCounters counters_;
};

inline canopen::CanopenMasterConfig bench_config() {
  canopen::CanopenMasterConfig c;
  c.drive_node_id = 3;
  c.load_cell_node_id = 4;
  c.spool = SpoolGeometry{0.01, 4096.0 * 109.0, 1.0};
  return c;
}

class Bench {
 public:
  static constexpr std::int64_t kCycleNs = 1'000'000;

  explicit Bench(const canopen::CanopenMasterConfig& config = bench_config())
      : master(bus, config), drive(config.drive_node_id), load_cell(config.load_cell_node_id) {}

  void power_on() {
    FrameOut out;
    drive.boot(clock.now_ns(), out);
    load_cell.boot(clock.now_ns(), out);
    to_master(out);
  }

  // Frames the master sent go to both devices, their answers back to the
  // master, until the bus is quiet.
  void deliver() {
    while (!bus.pending.empty()) {
      std::vector<CanFrame> sent;
      sent.swap(bus.pending);
      FrameOut out;
      for (const CanFrame& f : sent) {
        drive.on_frame(f, clock.now_ns(), out);
        load_cell.on_frame(f, clock.now_ns(), out);
      }
      to_master(out);
    }
  }

  void to_master(const FrameOut& frames) {
    for (const CanFrame& f : frames) {
      device_log.push_back(f);
      master.on_frame(f, clock.now_ns());
    }
  }

  // One control cycle as the end-cap application runs it.
  void cycle(double rest_length_m) {
    clock.advance_ns(kCycleNs);
    FrameOut out;
    drive.tick(clock.now_ns(), out);
    load_cell.tick(clock.now_ns(), out);
    to_master(out);
    master.poll(clock.now_ns());
    deliver();
    master.write_target(rest_length_m);
    master.send_sync();
    deliver();
  }

  // Cycles until `done` holds; false if it did not within max_cycles.
  bool run_until(const std::function<bool()>& done, int max_cycles, double rest_length_m = 1.0) {
    for (int i = 0; i < max_cycles; ++i) {
      if (done()) return true;
      cycle(rest_length_m);
    }
    return done();
  }

  std::vector<canopen::MasterEvent> take_events() {
    std::vector<canopen::MasterEvent> events;
    canopen::MasterEvent e;
    while (master.pop_event(e)) events.push_back(e);
    return events;
  }

  ManualClock clock{0};
  RecordingBus bus;
  canopen::CanopenMaster master;
  SimCia402Drive drive;
  SimLoadCell load_cell;
  std::vector<CanFrame> device_log;
};

}  // namespace tensegrity::fw::sim

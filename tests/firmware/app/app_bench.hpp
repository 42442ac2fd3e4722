// SPDX-License-Identifier: Apache-2.0
// The control loop of one end cap with two scripted drives and a load cell on an
// in-memory bus, paced by a ManualClock: deterministic, no sockets, no sleeping.
#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "firmware/app/control_loop.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "firmware/hal/clock.hpp"
#include "tests/firmware/drivers/sim_bus.hpp"

namespace tensegrity::fw::app::test {

// Host commands and tables queued by the test; telemetry kept (newest only).
class ScriptedHostLink final : public HostLink {
 public:
  bool try_take_table(HostTable& out) noexcept override {
    if (tables.empty()) return false;
    out = tables.front();
    tables.pop_front();
    return true;
  }
  bool try_take_command(HostCommand& out) noexcept override {
    if (commands.empty()) return false;
    out = commands.front();
    commands.pop_front();
    return true;
  }
  void publish(const Telemetry& t) noexcept override { last = t; }
  std::uint32_t emergency_stops() const noexcept override {
    if (before_estops_read) before_estops_read();  // what the node's thread does at that instant
    return estops;
  }
  std::uint32_t host_loss_stops() const noexcept override { return host_losses; }

  std::function<void()> before_estops_read;
  std::uint32_t estops = 0;
  std::uint32_t host_losses = 0;
  std::deque<HostTable> tables;
  std::deque<HostCommand> commands;
  Telemetry last;
};

inline LoopSettings bench_settings(LoopMode mode = LoopMode::realtime) {
  EndcapAppConfig c;
  c.bus = "udp:127.0.0.1:1";
  c.motor_count = 2;
  c.drive_node_ids = {3, 5, 0, 0};
  c.load_cell_node_id = 4;
  c.initial_rest_length_m = 0.95;
  c.mode = mode;
  c.load_cell_sample_timeout_s = 0.02;
  c.start_on_boot = true;
  return make_loop_settings(c);
}

// Square waves: motor 0 alternates 0.90/1.00 m, motor 1 1.00/0.90 m.
inline core::EndcapTable bench_table(double period_s = 0.2, double a_m = 0.90, double b_m = 1.00) {
  core::EndcapTable t;
  t.motor_count = 2;
  t.complexity = 2;
  t.period_s = period_s;
  t.rest_length_m[0][0] = a_m;
  t.rest_length_m[0][1] = b_m;
  t.rest_length_m[1][0] = b_m;
  t.rest_length_m[1][1] = a_m;
  return t;
}

struct AppBench {
  explicit AppBench(const LoopSettings& s = bench_settings()) : settings(s) {
    bus.attach(drive0);
    bus.attach(drive1);
    bus.attach(load_cell);
    load_cell.sample.tension_mn = {100'000, 120'000};  // 100 N, 120 N
    loop = std::make_unique<ControlLoop>(bus, clock, host, settings);
    bus.power_on();
  }

  // One realtime cycle: device heartbeats, then the loop (it sleeps to its deadline).
  void cycle() {
    bus.tick();
    loop->run_realtime_cycle();
    AppEvent e;
    while (loop->pop_event(e)) events.push_back(e);
  }
  bool run_until(const auto& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  bool running() const { return loop->controller().mode() == core::Mode::running; }
  // Brought up, table loaded and playing.
  bool start_running(const core::EndcapTable& table = bench_table()) {
    if (loop->load_table(table) != core::TableError::none) return false;
    return run_until([&] { return running(); }, 500);
  }
  bool has_event(AppEventKind kind) const {
    for (const AppEvent& e : events) {
      if (e.kind == kind) return true;
    }
    return false;
  }
  // The target drive i was last sent, as a rest length.
  double target_m(const sim::SimCia402Drive& d) const {
    return settings.master.spool.rest_length_from_counts(d.target_counts());
  }
  void send_emcy(sim::SimCia402Drive& d, std::uint16_t code) {
    sim::FrameOut out;
    d.inject_fault(code, clock.now_ns(), out);
    for (const CanFrame& f : out) bus.inject_to_receiver(f);
  }

  LoopSettings settings;
  ManualClock clock{1'000'000'000};
  sim::SimCanBus bus{clock};
  sim::SimCia402Drive drive0{3};
  sim::SimCia402Drive drive1{5};
  sim::SimLoadCell load_cell{4};
  ScriptedHostLink host;
  std::unique_ptr<ControlLoop> loop;
  std::vector<AppEvent> events;
};

}  // namespace tensegrity::fw::app::test

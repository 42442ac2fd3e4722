// SPDX-License-Identifier: Apache-2.0
#include "tests/firmware/comms/stub_loop.hpp"

#include <pthread.h>

#include <cmath>
#include <cstdio>

namespace tensegrity::test {

namespace {
core::EndcapConfig make_config(std::uint32_t motor_count) {
  core::EndcapConfig c;
  c.motor_count = motor_count;
  return c;
}
}  // namespace

StubLoop::StubLoop(int endcap, fw::app::HostLink& host, OffsetClock& clock, double rate_hz, std::uint32_t motor_count,
                   bool stall_commands)
    : endcap_(endcap),
      host_(host),
      clock_(clock),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / rate_hz))),
      controller_(make_config(motor_count)),
      stall_commands_(stall_commands) {
  for (auto& c : commanded_) c = controller_.config().initial_rest_length_m;
}

StubLoop::~StubLoop() { stop(); }

void StubLoop::start() {
  running_.store(true);
  thread_ = std::thread([this] { run(); });
}

void StubLoop::stop() {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
}

void StubLoop::run() {
  pthread_setname_np(pthread_self(), "loop");  // tests tell the loop's CPU from the node's by name
  origin_local_ns_ = clock_.now_ns();
  std::int64_t deadline = origin_local_ns_;
  std::int64_t previous = 0;
  while (running_.load()) {
    deadline += period_ns_;
    clock_.sleep_until_ns(deadline);
    const std::int64_t loop_ns = clock_.now_ns() - origin_local_ns_;
    if (loop_ns + origin_local_ns_ > deadline + period_ns_) ++overruns_;
    cycle(loop_ns, static_cast<double>(loop_ns - previous) / 1e9);
    previous = loop_ns;
  }
}

void StubLoop::apply_estops(std::uint32_t estops) {
  if (estops == estops_seen_) return;
  estops_seen_ = estops;
  pending_start_ = false;
  controller_.trip(core::FaultCause::emergency_stop);
  std::printf("ESTOPPED endcap=%d true_ns=%lld\n", endcap_, true_now_ns());
}

void StubLoop::apply(const fw::app::HostCommand& command, std::int64_t loop_ns) {
  switch (command.kind) {
    case fw::app::CommandKind::start:
      if (command.start_time_ns > loop_ns) {
        pending_start_ = true;
        pending_start_ns_ = command.start_time_ns;
      } else if (controller_.start(command.start_time_ns)) {
        std::printf("STARTED endcap=%d true_ns=%lld late\n", endcap_,
                    static_cast<long long>(command.start_time_ns + origin_local_ns_ - clock_.offset_ns()));
      }
      break;
    case fw::app::CommandKind::stop:
      pending_start_ = false;
      controller_.stop();
      std::printf("STOPPED endcap=%d\n", endcap_);
      break;
    case fw::app::CommandKind::emergency_stop: controller_.trip(core::FaultCause::emergency_stop); break;
    case fw::app::CommandKind::clear_fault:
      if (controller_.fault() != core::FaultCause::none) {
        controller_.clear_fault();
        std::printf("CLEARED endcap=%d true_ns=%lld\n", endcap_, true_now_ns());
      }
      break;
  }
}

void StubLoop::cycle(std::int64_t loop_ns, double dt_s) {
  fw::app::HostCommand command;
  while (!stall_commands_ && host_.try_take_command(command)) {
    if (static_cast<std::int32_t>(command.estops_before - estops_seen_) > 0) apply_estops(command.estops_before);
    apply(command, loop_ns);
  }
  apply_estops(host_.emergency_stops());
  // As the real loop (firmware/app/control_loop.cpp): a loss while playing latches.
  if (host_.host_loss_stops() != host_loss_stops_seen_) {
    host_loss_stops_seen_ = host_.host_loss_stops();
    if (controller_.mode() == core::Mode::running || pending_start_) {
      pending_start_ = false;
      controller_.trip(core::FaultCause::host_lost);
      std::printf("HOSTLOST endcap=%d true_ns=%lld\n", endcap_, true_now_ns());
    }
  }
  if (pending_start_ && loop_ns >= pending_start_ns_) {
    pending_start_ = false;
    if (controller_.start(pending_start_ns_)) {
      std::printf("STARTED endcap=%d true_ns=%lld\n", endcap_,
                  static_cast<long long>(pending_start_ns_ + origin_local_ns_ - clock_.offset_ns()));
    }
  }
  std::fflush(stdout);
  fw::app::HostTable table;
  while (host_.try_take_table(table)) {
    ack_sequence_ = table.sequence;
    ack_error_ = controller_.load(table.table);
  }
  const std::uint32_t n = controller_.config().motor_count;
  std::array<double, core::kMaxMotorsPerEndcap> tension{};
  tension.fill(100.0);
  const core::StepStatus step = controller_.step(loop_ns, dt_s, {tension.data(), n}, {commanded_.data(), n});
  ++cycles_;
  fw::app::Telemetry t;
  t.time_ns = loop_ns;
  t.cycle = cycles_;
  t.mode = controller_.mode();
  t.fault = controller_.fault();
  t.motor_count = n;
  t.subinterval = step.subinterval;
  t.cutoff_mask = step.cutoff_mask;
  t.drives_enabled = true;
  t.has_table = controller_.has_table();
  for (std::uint32_t m = 0; m < n; ++m) {
    t.commanded_rest_length_m[m] = commanded_[m];
    t.measured_rest_length_m[m] = commanded_[m];  // ideal plant
    t.tension_n[m] = tension[m];
  }
  t.table_ack_sequence = ack_sequence_;
  t.table_ack_error = ack_error_;
  t.overruns = overruns_;
  host_.publish(t);
}

}  // namespace tensegrity::test

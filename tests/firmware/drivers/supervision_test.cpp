// SPDX-License-Identifier: Apache-2.0
// Supervision the other way round: the master produces its own heartbeat and, in
// bring-up, tells each drive to watch it (0x1016) and what to do when it stops
// (0x6007); the emulated drive then stops its motor by itself when the master
// falls silent.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "bench_steps.hpp"
#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/sdo_codec.hpp"

namespace tensegrity::fw::canopen {
namespace {

using sim::Bench;

// Every SDO download the master sent to `node`, in order.
std::vector<SdoMessage> downloads(const Bench& b, std::uint8_t node) {
  std::vector<SdoMessage> out;
  for (const CanFrame& f : b.bus.log) {
    SdoMessage m;
    if (f.id == cob_id(Function::sdo_rx, node) && decode_sdo(f, false, m) && m.kind == SdoKind::download_request) {
      out.push_back(m);
    }
  }
  return out;
}

TEST(CanopenSupervision, EndCapHeartbeatEveryProducerPeriodFromBringUp) {
  Bench b;
  const std::uint32_t hb_id = cob_id(Function::heartbeat, 127);
  b.power_on();
  for (int i = 0; i < 20; ++i) b.cycle(1.0);
  EXPECT_EQ(std::count_if(b.bus.log.begin(), b.bus.log.end(), [&](const CanFrame& f) { return f.id == hb_id; }), 0)
      << "silent until bring-up starts";
  bring_up(b);
  b.bus.log.clear();
  const std::int64_t t0 = b.clock.now_ns();
  std::vector<std::int64_t> sent_at;
  for (int i = 0; i < 100; ++i) {
    const std::size_t before = b.bus.log.size();
    b.cycle(1.0);
    for (std::size_t k = before; k < b.bus.log.size(); ++k) {
      const CanFrame& f = b.bus.log[k];
      if (f.id != hb_id) continue;
      ASSERT_EQ(f.dlc, 1);
      EXPECT_EQ(f.data[0], static_cast<std::uint8_t>(NmtState::operational));
      sent_at.push_back(b.clock.now_ns() - t0);
    }
  }
  ASSERT_EQ(sent_at.size(), 10U) << "10 ms producer period over 100 ms";
  for (std::size_t i = 1; i < sent_at.size(); ++i) EXPECT_EQ(sent_at[i] - sent_at[i - 1], 10'000'000);
  EXPECT_GE(b.master.heartbeats_sent(), 10U);
  EXPECT_EQ(b.master.rx_drops().total(), 0U);
}

TEST(CanopenSupervision, BringUpWritesConsumerHeartbeatAndAbortOptionBeforeStart) {
  Bench b;
  bring_up(b);
  std::vector<SdoMessage> d = downloads(b, 3);
  ASSERT_EQ(d.size(), 7U);
  EXPECT_EQ(d[0].address.index, kOdProducerHeartbeatTime);
  d.erase(d.begin());
  EXPECT_EQ(d[0].address.index, kOdModesOfOperation);
  // The SYNC period (BringUpGivesTheDriveTheSyncPeriod checks the values).
  EXPECT_EQ(d[1].address.index, kOdCommunicationCyclePeriod);
  EXPECT_EQ(d[2].address.index, kOdInterpolationTimePeriod);
  EXPECT_EQ(d[3].address.index, kOdInterpolationTimePeriod);
  d.erase(d.begin() + 1, d.begin() + 4);
  EXPECT_EQ(d[1].address.index, kOdConsumerHeartbeatTime);
  EXPECT_EQ(d[1].address.subindex, 1);
  EXPECT_EQ(d[1].size, 4);
  EXPECT_EQ(d[1].value, (127U << 16) | 50U) << "watch node 127 with 50 ms";
  EXPECT_EQ(d[2].address.index, kOdAbortConnectionOption);
  EXPECT_EQ(d[2].size, 2);
  EXPECT_EQ(d[2].value, 3U) << "quick stop";
  // The drive took them.
  EXPECT_EQ(b.drive.consumer_node(), 127);
  EXPECT_EQ(b.drive.consumer_time_ms(), 50);
  EXPECT_EQ(b.drive.abort_connection_option(), AbortConnectionOption::quick_stop);
  EXPECT_TRUE(b.drive.consumer_armed()) << "armed by the end cap's heartbeats";
  // Before the NMT start: a drive never runs operational unsupervised.
  std::size_t last_sdo = 0, start = 0;
  for (std::size_t i = 0; i < b.bus.log.size(); ++i) {
    const CanFrame& f = b.bus.log[i];
    if (f.id == cob_id(Function::sdo_rx, 3)) last_sdo = i;
    if (f.id == 0 && f.data[0] == static_cast<std::uint8_t>(NmtCommand::start) && start == 0) start = i;
  }
  EXPECT_LT(last_sdo, start);
}

TEST(CanopenSupervision, ConfiguredTimesAndOptionAreWhatIsWritten) {
  CanopenMasterConfig c = sim::bench_config();
  c.master_node_id = 100;
  c.drive_consumer_heartbeat_ms = 80;
  c.drive_abort_connection = AbortConnectionOption::disable_voltage;
  Bench b(c);
  bring_up(b);
  EXPECT_EQ(b.drive.consumer_node(), 100);
  EXPECT_EQ(b.drive.consumer_time_ms(), 80);
  EXPECT_EQ(b.drive.abort_connection_option(), AbortConnectionOption::disable_voltage);
}

TEST(CanopenSupervision, BringUpWritesTheProducerTimeOfEveryNodeFirst) {
  CanopenMasterConfig c = sim::bench_config();
  c.node_heartbeat_period_ms = 15;
  Bench b(c);
  b.drive.script.heartbeat_period_ns = 500'000'000;  // factory defaults the end cap must not rely on
  b.load_cell.script.heartbeat_period_ns = 0;
  bring_up(b);
  for (const std::uint8_t node : {c.drive_node_id, c.load_cell_node_id}) {
    const std::vector<SdoMessage> written = downloads(b, node);
    ASSERT_FALSE(written.empty()) << "node " << int{node};
    EXPECT_EQ(written.front().address.index, kOdProducerHeartbeatTime) << "before anything the heartbeat times";
    EXPECT_EQ(written.front().value, 15U);
    EXPECT_EQ(written.front().size, 2U);
  }
  EXPECT_EQ(b.drive.heartbeat_period_ns(), 15'000'000);
  EXPECT_EQ(b.load_cell.heartbeat_period_ns(), 15'000'000);
}

TEST(CanopenSupervision, NoProducerTimeWrittenWhenItIsZero) {
  CanopenMasterConfig c = sim::bench_config();
  c.node_heartbeat_period_ms = 0;
  Bench b(c);
  bring_up(b);
  for (const SdoMessage& m : downloads(b, 3)) EXPECT_NE(m.address.index, kOdProducerHeartbeatTime);
  EXPECT_TRUE(downloads(b, 4).empty());
}

TEST(CanopenSupervision, BringUpFailsNamingTheLoadCellWhenItRefusesTheProducerTime) {
  Bench b;
  b.load_cell.script.sdo_abort_all = 0x0601'0002;  // read only
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::failed; }, 300));
  const std::string failure = b.master.bring_up_failure();
  EXPECT_NE(failure.find("load cell 4"), std::string::npos) << failure;
  EXPECT_NE(failure.find("0x1017"), std::string::npos) << failure;
}

TEST(CanopenSupervision, NoConsumerConfiguredWhenItsTimeIsZero) {
  CanopenMasterConfig c = sim::bench_config();
  c.drive_consumer_heartbeat_ms = 0;
  Bench b(c);
  bring_up(b);
  EXPECT_EQ(downloads(b, 3).size(), 5U) << "0x1017, 0x6060 and the SYNC period's 0x1006 and 0x60C2 (2) only";
  EXPECT_EQ(b.drive.consumer_time_ms(), 0);
}

TEST(CanopenSupervision, BringUpFailsNamingTheObjectWhenTheDriveRefusesTheConsumer) {
  // A drive without a heartbeat consumer: the end cap must not run it unsupervised.
  Bench b;
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  // Refuse every SDO from the moment the mode is checked.
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::set_heartbeat_consumer; }, 100));
  b.drive.script.sdo_abort_all = 0x0602'0000;
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::failed; }, 100));
  EXPECT_NE(std::string(b.master.bring_up_failure()).find("0x1016"), std::string::npos) << b.master.bring_up_failure();
  EXPECT_EQ(b.drive.nmt_state(), NmtState::pre_operational) << "never started";
}

TEST(CanopenSupervision, DriveQuickStopsWhenTheEndCapFallsSilent) {
  Bench b;
  bring_up(b);
  for (int i = 0; i < 30; ++i) b.cycle(1.0);
  ASSERT_EQ(b.drive.state(), Cia402State::operation_enabled);
  // The end cap's loop hangs: time goes on for the drive, the master says nothing.
  const std::int64_t last_heard = b.drive.last_consumed_heartbeat_ns();
  sim::FrameOut out;
  int ticks = 0;
  while (b.drive.heartbeat_losses() == 0 && ticks < 200) {
    b.clock.advance_ns(Bench::kCycleNs);
    b.drive.tick(b.clock.now_ns(), out);
    ++ticks;
  }
  ASSERT_EQ(b.drive.heartbeat_losses(), 1U);
  const std::int64_t detected_after = b.drive.heartbeat_lost_ns() - last_heard;
  EXPECT_GT(detected_after, 50'000'000);
  EXPECT_LE(detected_after, 51'000'000) << "within the consumer time and one tick";
  EXPECT_EQ(b.drive.state(), Cia402State::quick_stop_active) << "0x6007 = 3, at detection";
  EXPECT_EQ(b.drive.left_enabled_ns(), b.drive.heartbeat_lost_ns());
  EXPECT_FALSE(b.drive.follows_target());
}

TEST(CanopenSupervision, FaultOptionFaultsTheDriveWithAHeartbeatEmcy) {
  CanopenMasterConfig c = sim::bench_config();
  c.drive_abort_connection = AbortConnectionOption::fault_signal;
  Bench b(c);
  bring_up(b);
  sim::FrameOut out;
  for (int i = 0; i < 60; ++i) {
    b.clock.advance_ns(Bench::kCycleNs);
    b.drive.tick(b.clock.now_ns(), out);
  }
  EXPECT_EQ(b.drive.heartbeat_losses(), 1U);
  EXPECT_EQ(b.drive.last_fault_code(), 0x8130);
  EXPECT_EQ(b.drive.state(), Cia402State::fault);
}

TEST(CanopenSupervision, ARebootedDriveForgetsItsConsumerAndComesBackUnpowered) {
  Bench b;
  bring_up(b);
  b.take_events();
  const std::uint32_t boot_ups = b.master.heartbeat(NodeRole::drive).boot_ups;
  sim::FrameOut out;
  b.drive.reboot(b.clock.now_ns(), out);
  b.to_master(out);
  EXPECT_EQ(b.drive.state(), Cia402State::switch_on_disabled);
  EXPECT_EQ(b.drive.nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(b.drive.consumer_time_ms(), 0) << "0x1016 back at its power-on value";
  const auto events = b.take_events();
  EXPECT_TRUE(std::any_of(events.begin(), events.end(),
                          [](const MasterEvent& e) { return e.kind == MasterEventKind::boot_up && e.node_id == 3; }));
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).boot_ups, boot_ups + 1);
}

}  // namespace
}  // namespace tensegrity::fw::canopen

// SPDX-License-Identifier: Apache-2.0
// A SUPERball end cap winds two cables, so its master runs two CiA 402 drives
// (one per motor) next to the load cell. These tests hold the multi-drive
// behaviour; drive 0 alone keeps the single-drive API of the other tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/hal/clock.hpp"
#include "tests/firmware/drivers/sim_bus.hpp"

namespace tensegrity::fw::canopen {
namespace {

CanopenMasterConfig two_drive_config() {
  CanopenMasterConfig c;
  c.drive_node_id = 3;
  c.drive_count = 2;
  c.extra_drive_node_ids = {5, 0, 0};
  c.load_cell_node_id = 4;
  c.spool = SpoolGeometry{0.01, 4096.0 * 109.0, 1.0};
  return c;
}

struct TwoDriveBench {
  TwoDriveBench() {
    bus.attach(drive0);
    bus.attach(drive1);
    bus.attach(load_cell);
  }
  // The application's cycle: drain, poll, write both targets, SYNC.
  void cycle(double length0_m, double length1_m) {
    clock.advance_ns(1'000'000);
    bus.tick();
    CanFrame f;
    while (bus.receive(f, 0) == CanResult::ok) master.on_frame(f, clock.now_ns());
    master.poll(clock.now_ns());
    master.write_target(0, length0_m);
    master.write_target(1, length1_m);
    master.send_sync();
    MasterEvent e;
    while (master.pop_event(e)) events.push_back(e);
  }
  bool bring_up() {
    bus.power_on();
    master.start_bring_up(clock.now_ns());
    for (int i = 0; i < 300 && master.bring_up_step() != BringUpStep::done; ++i) cycle(1.0, 1.0);
    return master.bring_up_step() == BringUpStep::done;
  }
  bool has_event(MasterEventKind kind, std::uint8_t node) const {
    return std::any_of(events.begin(), events.end(),
                       [&](const MasterEvent& e) { return e.kind == kind && e.node_id == node; });
  }

  ManualClock clock{0};
  sim::SimCanBus bus{clock};
  CanopenMaster master{bus, two_drive_config()};
  sim::SimCia402Drive drive0{3};
  sim::SimCia402Drive drive1{5};
  sim::SimLoadCell load_cell{4};
  std::vector<MasterEvent> events;
};

TEST(CanopenMasterTwoDrives, BringUpSetsUpAndEnablesBothDrives) {
  TwoDriveBench b;
  ASSERT_TRUE(b.bring_up()) << to_string(b.master.bring_up_step()) << " " << b.master.bring_up_failure();
  EXPECT_EQ(b.master.drive_count(), 2U);
  EXPECT_EQ(b.drive0.mode(), kModeCyclicSynchronousPosition);
  EXPECT_EQ(b.drive1.mode(), kModeCyclicSynchronousPosition);
  EXPECT_EQ(b.drive0.state(), Cia402State::operation_enabled);
  EXPECT_EQ(b.drive1.state(), Cia402State::operation_enabled);
  EXPECT_TRUE(b.master.drive_heartbeat(1).alive);
}

TEST(CanopenMasterTwoDrives, EachDriveFollowsItsOwnTarget) {
  TwoDriveBench b;
  ASSERT_TRUE(b.bring_up());
  for (int i = 0; i < 3; ++i) b.cycle(0.99, 1.01);
  const SpoolGeometry& spool = b.master.config().spool;
  EXPECT_EQ(b.drive0.position_counts(), spool.counts_from_rest_length(0.99));
  EXPECT_EQ(b.drive1.position_counts(), spool.counts_from_rest_length(1.01));
  EXPECT_NEAR(b.master.drive(0).rest_length_m, 0.99, 1e-6);
  EXPECT_NEAR(b.master.drive(1).rest_length_m, 1.01, 1e-6);
  EXPECT_EQ(b.master.write_target(2, 1.0), CanResult::invalid_frame) << "no third drive";
}

TEST(CanopenMasterTwoDrives, FaultAndHeartbeatLossNameTheDrive) {
  TwoDriveBench b;
  ASSERT_TRUE(b.bring_up());
  sim::FrameOut out;
  b.drive1.inject_fault(0x2310, b.clock.now_ns(), out);
  for (const CanFrame& f : out) b.bus.inject_to_receiver(f);
  for (int i = 0; i < 3; ++i) b.cycle(1.0, 1.0);
  EXPECT_TRUE(b.has_event(MasterEventKind::emcy, 5));
  EXPECT_TRUE(b.has_event(MasterEventKind::drive_fault, 5));
  EXPECT_FALSE(b.has_event(MasterEventKind::drive_fault, 3));
  EXPECT_TRUE(b.master.drive(1).has_emcy);
  EXPECT_FALSE(b.master.drive(0).has_emcy);

  b.bus.set_connected(b.drive0, false);
  for (int i = 0; i < 150; ++i) b.cycle(1.0, 1.0);
  EXPECT_TRUE(b.has_event(MasterEventKind::heartbeat_lost, 3));
  EXPECT_FALSE(b.master.drive_heartbeat(0).alive);
  EXPECT_TRUE(b.master.drive_heartbeat(1).alive);
}

TEST(CanopenMasterTwoDrives, BringUpFailureNamesTheSecondDrive) {
  TwoDriveBench b;
  b.drive1.script.sdo_abort_all = 0x06090030;
  b.bus.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  for (int i = 0; i < 300 && b.master.bring_up_step() != BringUpStep::failed; ++i) b.cycle(1.0, 1.0);
  ASSERT_EQ(b.master.bring_up_step(), BringUpStep::failed);
  EXPECT_NE(std::string(b.master.bring_up_failure()).find("(drive 5)"), std::string::npos)
      << b.master.bring_up_failure();
}

}  // namespace
}  // namespace tensegrity::fw::canopen

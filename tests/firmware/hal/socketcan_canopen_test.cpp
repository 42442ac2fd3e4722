// SPDX-License-Identifier: Apache-2.0
// A CANopen exchange through the kernel's CAN stack: the end cap's master on one
// raw socket, an emulated CiA 402 drive and load cell on another, both on vcan0.
// Runs where the kernel has vcan (the VM of tests/vm, or a host with vcan0) and
// skips with the reason elsewhere.
#include <gtest/gtest.h>
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/hal/clock.hpp"
#include "firmware/hal/socketcan_bus.hpp"
#include "hil/devices/cia402_drive.hpp"
#include "hil/devices/load_cell.hpp"

namespace tensegrity::fw {
namespace {

using canopen::BringUpStep;
using canopen::Cia402State;

std::string vcan_interface() {
  const char* env = std::getenv("TENSEGRITY_VCAN_IF");
  return env != nullptr && *env != '\0' ? env : "vcan0";
}

// Both ends of one vcan interface, stepped one control cycle at a time.
struct VcanRig {
  std::unique_ptr<SocketCanBus> master_bus;
  std::unique_ptr<SocketCanBus> device_bus;
  ManualClock clock{0};
  canopen::CanopenMasterConfig config = [] {
    canopen::CanopenMasterConfig c;
    c.drive_node_id = 3;
    c.load_cell_node_id = 4;
    c.spool = SpoolGeometry{0.01, 4096.0 * 109.0, 1.0};
    return c;
  }();
  std::unique_ptr<canopen::CanopenMaster> master;
  hil::SimCia402Drive drive{3};
  hil::SimLoadCell load_cell{4};
  int frames_to_devices = 0;
  int frames_to_master = 0;

  void send_all(const hil::FrameOut& out) {
    for (const CanFrame& f : out) ASSERT_EQ(device_bus->send(f), CanResult::ok);
  }
  // Moves frames until both sockets have been quiet for 2 ms.
  void settle() {
    for (bool moved = true; moved;) {
      moved = false;
      CanFrame f;
      while (device_bus->receive(f, 2'000'000) == CanResult::ok) {
        hil::FrameOut out;
        drive.on_frame(f, clock.now_ns(), out);
        load_cell.on_frame(f, clock.now_ns(), out);
        send_all(out);
        ++frames_to_devices;
        moved = true;
      }
      while (master_bus->receive(f, 2'000'000) == CanResult::ok) {
        master->on_frame(f, clock.now_ns());
        ++frames_to_master;
        moved = true;
      }
    }
  }
  void cycle(double rest_length_m) {
    clock.advance_ns(1'000'000);
    hil::FrameOut out;
    drive.tick(clock.now_ns(), out);
    load_cell.tick(clock.now_ns(), out);
    send_all(out);
    settle();
    master->poll(clock.now_ns());
    master->write_target(rest_length_m);
    master->send_sync();
    settle();
  }
};

TEST(SocketCanCanopen, MasterBringsUpAnEmulatedDriveOverVcan) {
  const int probe = ::socket(AF_CAN, SOCK_RAW, CAN_RAW);
  if (probe < 0) GTEST_SKIP() << "kernel has no CAN support: socket(AF_CAN) failed: " << std::strerror(errno);
  ::close(probe);
  VcanRig rig;
  std::string error;
  rig.master_bus = SocketCanBus::open(vcan_interface(), error);
  if (!rig.master_bus) GTEST_SKIP() << error;
  rig.device_bus = SocketCanBus::open(vcan_interface(), error);
  ASSERT_NE(rig.device_bus, nullptr) << error;
  rig.master = std::make_unique<canopen::CanopenMaster>(*rig.master_bus, rig.config);

  hil::FrameOut boot;
  rig.drive.boot(0, boot);
  rig.load_cell.boot(0, boot);
  rig.send_all(boot);
  rig.master->start_bring_up(rig.clock.now_ns());
  for (int i = 0; i < 300 && rig.master->bring_up_step() != BringUpStep::done &&
                  rig.master->bring_up_step() != BringUpStep::failed;
       ++i) {
    rig.cycle(1.0);
  }
  ASSERT_EQ(rig.master->bring_up_step(), BringUpStep::done) << rig.master->bring_up_failure();
  EXPECT_EQ(rig.drive.state(), Cia402State::operation_enabled);
  EXPECT_EQ(rig.master->drive().state, Cia402State::operation_enabled);

  // Cyclic synchronous position: the target goes out as RPDO1, the drive reaches it
  // at SYNC and reports it back in TPDO1.
  rig.load_cell.sample.tension_mn = {123'456, 78'900};
  for (int i = 0; i < 5; ++i) rig.cycle(0.9);
  EXPECT_NEAR(rig.master->drive().rest_length_m, 0.9, 1e-6);
  EXPECT_NEAR(rig.master->load_cell().tension_n[0], 123.456, 1e-9);
  EXPECT_NEAR(rig.master->load_cell().tension_n[1], 78.9, 1e-9);
  EXPECT_EQ(rig.master->rx_drops().total(), 0U);
  EXPECT_GT(rig.frames_to_devices, 10);
  EXPECT_GT(rig.frames_to_master, 10);
}

}  // namespace
}  // namespace tensegrity::fw

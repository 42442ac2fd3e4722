// SPDX-License-Identifier: Apache-2.0
// The HIL's device emulation without sockets: the drive's position from outside,
// explicit TPDOs, the start gate, faults; the load cell's model tensions, stuck
// and drifting; an end cap's preferred rest lengths (follow, hold, release).
#include <gtest/gtest.h>

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/nmt.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "hil/endcap_devices.hpp"

namespace tensegrity::hil {
namespace {

using namespace fw::canopen;

CanFrame rpdo(std::uint8_t node, std::uint16_t cw, std::int32_t target) {
  return encode_drive_rpdo1(node, {cw, target});
}

// Power on, NMT start, CSP by SDO-free shortcut (od_write through SDO is tested in
// the driver tests), then the CiA 402 power-up controlwords.
void operational(SimNode& node, FrameOut& out) {
  node.boot(0, out);
  node.on_frame(encode_nmt(NmtCommand::start, node.node_id()), 0, out);
}

void power_up(SimCia402Drive& d, FrameOut& out) {
  d.on_frame(rpdo(d.node_id(), 0x06, 0), 0, out);
  d.on_frame(rpdo(d.node_id(), 0x07, 0), 0, out);
  d.on_frame(rpdo(d.node_id(), 0x0F, 0), 0, out);
}

void set_csp(SimCia402Drive& d, FrameOut& out) {
  d.on_frame(encode_sdo(d.node_id(), {SdoKind::download_request, {kOdModesOfOperation, 0}, 8, 1}), 0, out);
}

TEST(HilDrive, PositionFromOutsideAndTpdosOnlyWhenAsked) {
  SimCia402Drive d(1);
  d.ideal_position = false;
  d.tpdo_on_sync = false;
  FrameOut out;
  operational(d, out);
  set_csp(d, out);
  power_up(d, out);
  out.clear();
  d.set_actual(1234, -5);
  d.on_frame(encode_sync(0), 0, out);
  EXPECT_TRUE(out.empty()) << "TPDOs must wait for emit_tpdos() in lockstep";
  d.emit_tpdos(out);
  ASSERT_EQ(out.size(), 2u);
  DriveTpdo1 t1;
  ASSERT_TRUE(decode_drive_tpdo1(out[0], t1));
  EXPECT_EQ(t1.actual_position_counts, 1234);
  DriveTpdo2 t2;
  ASSERT_TRUE(decode_drive_tpdo2(out[1], t2));
  EXPECT_EQ(t2.actual_velocity_counts_per_s, -5);
  // The target does not move the position: the model does.
  d.on_frame(rpdo(1, 0x0F, 999), 0, out);
  d.on_frame(encode_sync(0), 0, out);
  EXPECT_EQ(d.position_counts(), 1234);
  EXPECT_EQ(d.target_counts(), 999);
}

TEST(HilDrive, StartGateHoldsEnableUntilReleased) {
  SimCia402Drive d(3);
  d.hold_enable = true;
  FrameOut out;
  operational(d, out);
  set_csp(d, out);
  power_up(d, out);
  EXPECT_EQ(d.state(), Cia402State::switched_on);
  EXPECT_TRUE(d.at_enable_gate());
  EXPECT_FALSE(d.follows_target());
  d.release_enable_gate();
  EXPECT_EQ(d.state(), Cia402State::operation_enabled);
  EXPECT_TRUE(d.follows_target());
}

TEST(HilDrive, FaultSendsEmcyAndStopsFollowing) {
  SimCia402Drive d(1);
  FrameOut out;
  operational(d, out);
  set_csp(d, out);
  power_up(d, out);
  ASSERT_TRUE(d.follows_target());
  out.clear();
  d.inject_fault(0x2310, 0, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, cob_id(Function::sync_or_emcy, 1));
  EXPECT_FALSE(d.follows_target());
  d.tick(1, out);
  EXPECT_EQ(d.state(), Cia402State::fault);
}

TEST(HilDrive, SilentDriveSaysNothing) {
  SimCia402Drive d(1);
  d.tpdo_on_sync = true;
  FrameOut out;
  operational(d, out);
  d.script.silent = true;
  out.clear();
  d.tick(1'000'000'000, out);
  d.on_frame(encode_sync(0), 0, out);
  d.emit_tpdos(out);
  d.on_frame(encode_sdo(1, {SdoKind::upload_request, {kOdStatusword, 0}, 0, 0}), 0, out);
  EXPECT_TRUE(out.empty());
}

TEST(HilLoadCell, ModelTensionsStuckAndDrift) {
  SimLoadCell lc(2);
  lc.tpdo_on_sync = false;
  FrameOut out;
  operational(lc, out);
  out.clear();
  lc.set_tensions_n(12.3456, 78.9, 0);
  lc.emit_tpdo(out);
  LoadCellTpdo1 s;
  ASSERT_TRUE(decode_load_cell_tpdo1(out.back(), s));
  EXPECT_EQ(s.tension_mn[0], 12346);
  EXPECT_EQ(s.tension_mn[1], 78900);
  const std::uint8_t seq = s.sequence;
  lc.set_stuck(true);
  lc.set_tensions_n(50.0, 50.0, 0);
  lc.emit_tpdo(out);
  ASSERT_TRUE(decode_load_cell_tpdo1(out.back(), s));
  EXPECT_EQ(s.sequence, seq) << "a stuck sensor repeats its sequence number";
  EXPECT_EQ(s.tension_mn[0], 12346);
  lc.set_stuck(false);
  lc.start_drift(2.0, 0);
  lc.set_tensions_n(10.0, 10.0, 500'000'000);  // 0.5 s later: +1 N
  lc.emit_tpdo(out);
  ASSERT_TRUE(decode_load_cell_tpdo1(out.back(), s));
  EXPECT_EQ(s.tension_mn[0], 11000);
}

TEST(HilEndcapDevices, FollowHoldRelease) {
  const fw::SpoolGeometry spool{0.01, 4096.0 * 109.0, 0.95};
  EndcapDevices dev(0, {0, 2}, spool, 1.1, true);
  FrameOut out;
  dev.power_on(0, out);
  for (std::size_t m = 0; m < 2; ++m) {
    dev.on_frame(encode_nmt(NmtCommand::start, 0), 0, out);
    set_csp(dev.drive(m), out);
  }
  std::vector<double> rest(24, 0.95), pref(24, 0.0);
  dev.preferred(rest, pref);
  EXPECT_DOUBLE_EQ(pref[0], 0.95) << "a drive that is not enabled holds its cable";
  for (const std::uint16_t cw : {std::uint16_t{0x06}, std::uint16_t{0x07}, std::uint16_t{0x0F}}) {
    dev.on_frame(rpdo(1, cw, 0), 0, out);
    dev.on_frame(rpdo(3, cw, 0), 0, out);
  }
  EXPECT_TRUE(dev.at_gate());
  dev.release_gate();
  dev.clear_rpdo_marks();
  EXPECT_FALSE(dev.all_rpdos());
  EXPECT_EQ(dev.missing_rpdo_nodes(), "1, 3");
  const std::int32_t target = spool.counts_from_rest_length(0.9);
  dev.on_frame(rpdo(1, 0x0F, target), 0, out);
  EXPECT_EQ(dev.missing_rpdo_nodes(), "3");
  dev.on_frame(rpdo(3, 0x0F, 0), 0, out);
  EXPECT_TRUE(dev.all_rpdos());
  dev.preferred(rest, pref);
  EXPECT_NEAR(pref[0], 0.9, 1.0 / spool.counts_per_m());
  EXPECT_NEAR(pref[2], 0.95, 1e-12);
  dev.fault_drive(0, 0x2310, true, 0, out);
  dev.fault_drive(1, 0x2310, false, 0, out);
  rest[2] = 0.93;
  dev.preferred(rest, pref);
  EXPECT_DOUBLE_EQ(pref[0], 1.1) << "released: the spool runs free to its end stop";
  EXPECT_DOUBLE_EQ(pref[2], 0.93) << "faulted, brake on: holds where it is";
}

// The drive watches the end cap's heartbeat (0x1016, written by SDO as the end
// cap's bring-up does) and takes its 0x6007 action when it stops; the HIL's start
// gate, which stops the end cap's time, is not mistaken for silence.
TEST(HilDrive, HonoursConsumerHeartbeatAndAbortConnection) {
  SimCia402Drive d(1);
  FrameOut out;
  operational(d, out);
  set_csp(d, out);
  d.on_frame(encode_sdo(1, {SdoKind::download_request, {kOdConsumerHeartbeatTime, 1}, (127U << 16) | 30U, 4}), 0, out);
  d.on_frame(encode_sdo(1, {SdoKind::download_request, {kOdAbortConnectionOption, 0}, 3, 2}), 0, out);
  EXPECT_EQ(d.consumer_time_ms(), 30);
  EXPECT_EQ(d.abort_connection_option(), AbortConnectionOption::quick_stop);
  power_up(d, out);
  ASSERT_EQ(d.state(), Cia402State::operation_enabled);
  for (std::int64_t t = 0; t <= 100'000'000; t += 1'000'000) d.tick(t, out);
  EXPECT_EQ(d.heartbeat_losses(), 0u) << "monitoring starts with the first heartbeat";
  d.on_frame(encode_heartbeat(127, NmtState::operational), 100'000'000, out);
  d.on_frame(encode_heartbeat(126, NmtState::operational), 120'000'000, out);  // another node's: ignored
  for (std::int64_t t = 100'000'000; t <= 130'000'000; t += 1'000'000) d.tick(t, out);
  EXPECT_EQ(d.state(), Cia402State::operation_enabled) << "30 ms is not yet more than 30 ms";
  d.tick(131'000'000, out);
  EXPECT_EQ(d.heartbeat_losses(), 1u);
  EXPECT_EQ(d.heartbeat_lost_ns(), 131'000'000);
  EXPECT_EQ(d.state(), Cia402State::quick_stop_active);
  EXPECT_EQ(d.left_enabled_ns(), 131'000'000);
  // Refused values are SDO aborts.
  out.clear();
  d.on_frame(encode_sdo(1, {SdoKind::download_request, {kOdAbortConnectionOption, 0}, 9, 2}), 0, out);
  SdoMessage m;
  ASSERT_TRUE(decode_sdo(out.back(), true, m));
  EXPECT_EQ(m.kind, SdoKind::abort);
}

TEST(HilDrive, StartGatePauseIsNotSilence) {
  SimCia402Drive d(1);
  d.hold_enable = true;
  FrameOut out;
  operational(d, out);
  set_csp(d, out);
  d.on_frame(encode_sdo(1, {SdoKind::download_request, {kOdConsumerHeartbeatTime, 1}, (127U << 16) | 30U, 4}), 0, out);
  d.on_frame(encode_sdo(1, {SdoKind::download_request, {kOdAbortConnectionOption, 0}, 3, 2}), 0, out);
  d.on_frame(encode_heartbeat(127, NmtState::operational), 0, out);
  power_up(d, out);
  ASSERT_TRUE(d.at_enable_gate());
  d.release_enable_gate();  // four seconds of device time later, no tick in between
  d.tick(4'000'000'000, out);
  EXPECT_EQ(d.heartbeat_losses(), 0u);
  EXPECT_EQ(d.state(), Cia402State::operation_enabled);
  d.tick(4'031'000'000, out);
  EXPECT_EQ(d.state(), Cia402State::quick_stop_active) << "and monitoring goes on from there";
}

TEST(HilEndcapDevices, RebootedDriveComesBackPreOperationalAndUnpowered) {
  const fw::SpoolGeometry spool{0.01, 4096.0 * 109.0, 0.95};
  EndcapDevices dev(0, {0, 2}, spool, 1.1, true);
  FrameOut out;
  dev.power_on(0, out);
  dev.on_frame(encode_nmt(NmtCommand::start, 0), 0, out);
  out.clear();
  dev.reboot_drive(1, 5'000'000, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x700u + 3u);
  EXPECT_EQ(out[0].data[0], 0) << "boot-up";
  EXPECT_EQ(dev.drive(1).nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(dev.drive(1).state(), Cia402State::switch_on_disabled);
  EXPECT_EQ(dev.drive(1).reboots(), 1u);
  EXPECT_EQ(dev.drive(0).nmt_state(), NmtState::operational);
  out.clear();
  dev.emit_sensors(out);
  for (const CanFrame& f : out) EXPECT_NE(f.id, 0x180u + 3u) << "no TPDO from a pre-operational drive";
  out.clear();
  dev.reboot_load_cell(6'000'000, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x700u + kLoadCellNodeId);
}

}  // namespace
}  // namespace tensegrity::hil

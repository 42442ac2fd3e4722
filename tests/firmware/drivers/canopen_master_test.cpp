// SPDX-License-Identifier: Apache-2.0
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bench_steps.hpp"
#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {
namespace {

using sim::Bench;
using ::testing::HasSubstr;

TEST(CanopenMaster, BootUpIsDetectedFromHeartbeatStateZero) {
  Bench b;
  b.power_on();
  const auto events = b.take_events();
  EXPECT_TRUE(has_event(events, MasterEventKind::boot_up, 3));
  EXPECT_TRUE(has_event(events, MasterEventKind::boot_up, 4));
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).boot_ups, 1U);
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).state, NmtState::pre_operational);
}

TEST(CanopenMaster, NmtStartMakesANodeOperational) {
  Bench b;
  b.power_on();
  ASSERT_EQ(b.master.send_nmt(NmtCommand::start, 3), CanResult::ok);
  b.deliver();
  EXPECT_EQ(b.drive.nmt_state(), NmtState::operational);
  EXPECT_EQ(b.load_cell.nmt_state(), NmtState::pre_operational) << "addressed to the drive only";
  ASSERT_TRUE(b.run_until([&] { return b.master.heartbeat(NodeRole::drive).state == NmtState::operational; }, 50));

  b.master.send_nmt(NmtCommand::reset_node, 0);
  b.deliver();
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).boot_ups, 2U);
  EXPECT_EQ(b.master.heartbeat(NodeRole::load_cell).boot_ups, 2U);
  EXPECT_EQ(b.drive.nmt_state(), NmtState::pre_operational);
}

TEST(CanopenMaster, TargetHoldsPositionUntilEnabledThenFollowsTheRestLength) {
  Bench b;
  b.power_on();
  b.master.send_nmt(NmtCommand::start, 0);
  b.master.sdo_download(NodeRole::drive, {kOdModesOfOperation, 0}, 8, 1, b.clock.now_ns());
  b.deliver();
  b.master.sdo_acknowledge(NodeRole::drive);
  b.cycle(0.9);  // commanded 10 cm shorter, but the drive is not enabled
  EXPECT_EQ(b.master.drive().target_sent_counts, 0);
  b.master.request_power(PowerRequest::operation_enabled);
  ASSERT_TRUE(b.run_until([&] { return b.master.drive().state == Cia402State::operation_enabled; }, 20, 0.9));
  EXPECT_EQ(b.drive.position_counts(), 0) << "enabling did not move the motor";

  const SpoolGeometry& spool = b.master.config().spool;
  b.cycle(0.999);
  b.cycle(0.998);
  EXPECT_EQ(b.drive.target_counts(), spool.counts_from_rest_length(0.998));
  EXPECT_NEAR(b.master.drive().rest_length_m, 0.998, 1e-6);
  EXPECT_NEAR(b.master.drive().rest_length_rate_m_per_s, -1.0, 1e-3) << "1 mm per 1 ms cycle";
}

TEST(CanopenMaster, NonFiniteTargetIsRefusedAndTheDriveHolds) {
  Bench b;
  bring_up(b);
  b.cycle(0.99);
  const std::int32_t held = b.drive.position_counts();
  b.cycle(std::nan(""));
  EXPECT_EQ(b.master.targets_refused(), 1U);
  EXPECT_EQ(b.drive.target_counts(), held);
}

TEST(CanopenMaster, FaultIsReportedAndClearedOnlyByFaultReset) {
  Bench b;
  bring_up(b);
  b.take_events();
  sim::FrameOut out;
  b.drive.inject_fault(0x2310, b.clock.now_ns(), out);
  b.to_master(out);
  b.run_until([] { return false; }, 5);
  EXPECT_EQ(b.master.drive().state, Cia402State::fault);
  auto events = b.take_events();
  ASSERT_TRUE(has_event(events, MasterEventKind::emcy, 3));
  const auto emcy =
      std::find_if(events.begin(), events.end(), [](const MasterEvent& e) { return e.kind == MasterEventKind::emcy; });
  EXPECT_EQ(emcy->emcy.error_code, 0x2310);
  EXPECT_EQ(emcy->emcy.error_register, kErrRegGeneric | kErrRegCurrent);
  EXPECT_STREQ(emcy_error_text(emcy->emcy.error_code), "continuous over-current");
  EXPECT_TRUE(has_event(events, MasterEventKind::drive_fault, 3));
  EXPECT_EQ(b.master.drive().last_emcy.error_code, 0x2310);

  b.run_until([] { return false; }, 20);
  EXPECT_EQ(b.drive.state(), Cia402State::fault) << "no automatic fault reset";

  b.master.request_fault_reset();
  ASSERT_TRUE(b.run_until([&] { return b.master.drive().state == Cia402State::operation_enabled; }, 20));
  EXPECT_TRUE(has_event(b.take_events(), MasterEventKind::drive_fault_cleared, 3));
}

TEST(CanopenMaster, SdoUploadAndDownload) {
  Bench b;
  b.power_on();
  ASSERT_TRUE(b.master.sdo_upload(NodeRole::drive, {0x1000, 0}, b.clock.now_ns()));
  EXPECT_FALSE(b.master.sdo_upload(NodeRole::drive, {0x1000, 0}, b.clock.now_ns())) << "one at a time";
  b.deliver();
  SdoTransfer t = b.master.sdo_transfer(NodeRole::drive);
  EXPECT_EQ(t.status, SdoStatus::done);
  EXPECT_EQ(t.value, 0x0002'0192U);
  EXPECT_EQ(t.size, 4);
  b.master.sdo_acknowledge(NodeRole::drive);

  ASSERT_TRUE(b.master.sdo_download(NodeRole::drive, {kOdModesOfOperation, 0}, 8, 1, b.clock.now_ns()));
  b.deliver();
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::drive).status, SdoStatus::done);
  EXPECT_EQ(b.drive.mode(), 8);
  b.master.sdo_acknowledge(NodeRole::drive);

  ASSERT_TRUE(b.master.sdo_upload(NodeRole::load_cell, {0x1000, 0}, b.clock.now_ns()));
  b.deliver();
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::load_cell).value, 0x0004'0194U);
  EXPECT_TRUE(has_event(b.take_events(), MasterEventKind::sdo_finished, 4));
}

TEST(CanopenMaster, SdoAbortIsDecoded) {
  Bench b;
  b.power_on();
  b.master.sdo_upload(NodeRole::drive, {0x2000, 0}, b.clock.now_ns());
  b.deliver();
  SdoTransfer t = b.master.sdo_transfer(NodeRole::drive);
  EXPECT_EQ(t.status, SdoStatus::aborted);
  EXPECT_TRUE(t.aborted_by_server);
  EXPECT_EQ(t.abort_code, sdo_abort::kNoObject);
  EXPECT_STREQ(sdo_abort::text(t.abort_code), "object does not exist in the object dictionary");
  b.master.sdo_acknowledge(NodeRole::drive);

  b.master.sdo_download(NodeRole::drive, {kOdStatusword, 0}, 0, 2, b.clock.now_ns());
  b.deliver();
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::drive).abort_code, sdo_abort::kReadOnly);
}

TEST(CanopenMaster, SdoTimeoutAbortsTheTransfer) {
  Bench b;
  b.power_on();
  b.drive.script.sdo_silent = true;
  b.master.sdo_upload(NodeRole::drive, {0x1000, 0}, b.clock.now_ns());
  b.deliver();
  for (int i = 0; i < 49; ++i) b.cycle(1.0);
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::drive).status, SdoStatus::pending) << "timeout is 50 ms";
  for (int i = 0; i < 2; ++i) b.cycle(1.0);
  const SdoTransfer& t = b.master.sdo_transfer(NodeRole::drive);
  EXPECT_EQ(t.status, SdoStatus::timed_out);
  EXPECT_EQ(t.abort_code, sdo_abort::kTimeout);
  // The server is told, with an abort on the client's COB-ID.
  const auto abort = std::find_if(b.bus.log.begin(), b.bus.log.end(),
                                  [](const CanFrame& f) { return f.id == 0x603 && f.data[0] == 0x80; });
  ASSERT_NE(abort, b.bus.log.end());
  EXPECT_EQ(abort->data[4] | abort->data[5] << 8 | abort->data[6] << 16 | abort->data[7] << 24,
            static_cast<int>(sdo_abort::kTimeout));
}

TEST(CanopenMaster, SegmentedUploadIsRefusedWithAnAbort) {
  Bench b;
  b.power_on();
  b.drive.script.sdo_segmented_upload = true;
  b.master.sdo_upload(NodeRole::drive, {0x1000, 0}, b.clock.now_ns());
  b.deliver();
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::drive).status, SdoStatus::aborted);
  EXPECT_EQ(b.master.sdo_transfer(NodeRole::drive).abort_code, sdo_abort::kBadCommand);
  EXPECT_FALSE(b.master.sdo_transfer(NodeRole::drive).aborted_by_server);
  EXPECT_EQ(b.bus.log.back().id, 0x603U);
  EXPECT_EQ(b.bus.log.back().data[0], 0x80);
}

TEST(CanopenMaster, HeartbeatLossIsDetectedAfterTheTimeout) {
  Bench b;
  bring_up(b);
  b.take_events();
  b.drive.script.heartbeat = false;
  const std::int64_t last_ns = b.master.heartbeat(NodeRole::drive).last_seen_ns;
  ASSERT_TRUE(b.run_until([&] { return !b.master.heartbeat(NodeRole::drive).alive; }, 200));
  const std::int64_t detected_after_ns = b.clock.now_ns() - last_ns;
  EXPECT_GT(detected_after_ns, 100'000'000);
  EXPECT_LE(detected_after_ns, 101'000'000);
  auto events = b.take_events();
  EXPECT_TRUE(has_event(events, MasterEventKind::heartbeat_lost, 3));
  EXPECT_FALSE(has_event(events, MasterEventKind::heartbeat_lost, 4));
  EXPECT_TRUE(b.master.heartbeat(NodeRole::load_cell).alive);
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).losses, 1U);

  b.drive.script.heartbeat = true;
  ASSERT_TRUE(b.run_until([&] { return b.master.heartbeat(NodeRole::drive).alive; }, 50));
  EXPECT_TRUE(has_event(b.take_events(), MasterEventKind::heartbeat_restored, 3));
}

TEST(CanopenMaster, LoadCellTensionAndStaleSamples) {
  Bench b;
  bring_up(b);
  b.load_cell.sample.tension_mn = {123'456, -1'000};
  b.load_cell.sample.status = kLoadCellCh0Valid | kLoadCellCh1Valid | kLoadCellCh1OverRange;
  b.cycle(1.0);
  const LoadCellStatus& lc = b.master.load_cell();
  EXPECT_DOUBLE_EQ(lc.tension_n[0], 123.456);
  EXPECT_DOUBLE_EQ(lc.tension_n[1], -1.0);
  EXPECT_TRUE(lc.valid[0]);
  EXPECT_FALSE(lc.valid[1]) << "over range";
  EXPECT_EQ(lc.updated_ns, b.clock.now_ns());
  EXPECT_EQ(lc.stale_samples, 0U);
  b.load_cell.advance_sequence = false;
  b.cycle(1.0);
  b.cycle(1.0);
  EXPECT_EQ(b.master.load_cell().stale_samples, 2U);
}

TEST(CanopenMaster, MalformedAndForeignFramesAreCountedAndIgnored) {
  Bench b;
  bring_up(b);
  const DriveStatus before = b.master.drive();
  const std::uint64_t accepted = b.master.frames_accepted();
  const auto feed = [&](CanFrame f) { b.master.on_frame(f, b.clock.now_ns()); };

  CanFrame ext = encode_drive_tpdo1(3, {0x0008, 1});
  ext.extended = true;
  feed(ext);
  CanFrame rtr = encode_heartbeat(3, NmtState::operational);
  rtr.rtr = true;
  feed(rtr);
  feed(encode_nmt(NmtCommand::stop, 3));     // another master's NMT
  feed(encode_drive_rpdo1(3, {0x0000, 0}));  // an RPDO echoed back
  feed(encode_drive_tpdo1(9, {0x0008, 1}));  // node 9 is not ours
  CanFrame short_tpdo = encode_drive_tpdo1(3, {0x0008, 1});
  short_tpdo.dlc = 4;
  feed(short_tpdo);
  feed(encode_drive_tpdo1(3, {0x0001, 1}));  // statusword matches no state
  CanFrame hb_long = encode_heartbeat(3, NmtState::operational);
  hb_long.dlc = 2;
  feed(hb_long);
  CanFrame hb_state = encode_heartbeat(3, NmtState::operational);
  hb_state.data[0] = 0x42;
  feed(hb_state);
  CanFrame emcy_short = encode_emcy(3, {0x1000, 1, {}});
  emcy_short.dlc = 3;
  feed(emcy_short);
  CanFrame lc_reserved = encode_load_cell_tpdo1(4, {});
  lc_reserved.data[6] = 0x80;
  feed(lc_reserved);
  feed(encode_drive_tpdo2(4, {}));                                     // load cell has no TPDO2
  feed(encode_sdo(3, {SdoKind::upload_response, {0x1000, 0}, 1, 4}));  // nothing pending
  CanFrame sync_long = encode_sync(1);
  sync_long.dlc = 2;
  feed(sync_long);
  CanFrame bad_dlc = encode_drive_tpdo1(3, {0x0008, 1});
  bad_dlc.dlc = 9;
  feed(bad_dlc);

  const RxDropCounters& d = b.master.rx_drops();
  EXPECT_EQ(d[RxDrop::extended_id], 1U);
  EXPECT_EQ(d[RxDrop::rtr], 1U);
  EXPECT_EQ(d[RxDrop::unexpected_function], 3U);
  EXPECT_EQ(d[RxDrop::unknown_node], 1U);
  EXPECT_EQ(d[RxDrop::bad_length], 5U);
  EXPECT_EQ(d[RxDrop::bad_value], 3U);
  EXPECT_EQ(d[RxDrop::unexpected_sdo], 1U);
  EXPECT_EQ(d.total(), 15U);
  EXPECT_EQ(b.master.frames_accepted(), accepted);
  EXPECT_EQ(b.master.drive().state, before.state);
  EXPECT_EQ(b.master.drive().position_counts, before.position_counts);
  EXPECT_EQ(b.master.heartbeat(NodeRole::drive).state, NmtState::operational);
  EXPECT_FALSE(b.master.drive().has_emcy);
}

TEST(CanopenMaster, SyncConsumerAndProducer) {
  CanopenMasterConfig config = sim::bench_config();
  config.sync_counter_max = 3;
  Bench b(config);
  b.master.on_frame(encode_sync(5), 42);
  EXPECT_EQ(b.master.sync().received, 1U);
  EXPECT_EQ(b.master.sync().last_counter, 5);
  EXPECT_EQ(b.master.sync().last_received_ns, 42);
  for (int i = 0; i < 4; ++i) b.master.send_sync();
  std::vector<int> counters;
  for (const CanFrame& f : b.bus.log) counters.push_back(f.data[0]);
  EXPECT_THAT(counters, ::testing::ElementsAre(1, 2, 3, 1));
  EXPECT_EQ(b.master.sync().sent, 4U);
}

}  // namespace
}  // namespace tensegrity::fw::canopen

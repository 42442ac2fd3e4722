// SPDX-License-Identifier: Apache-2.0
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/nmt.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "firmware/drivers/sdo_abort.hpp"
#include "firmware/drivers/sdo_codec.hpp"

namespace tensegrity::fw::canopen {
namespace {

using ::testing::ElementsAre;

std::vector<int> bytes(const CanFrame& f) { return {f.data.begin(), f.data.begin() + f.dlc}; }

TEST(PdoCodec, DriveRpdo1LayoutAndRoundTrip) {
  const DriveRpdo1 pdo{0x000F, -2};
  const CanFrame f = encode_drive_rpdo1(3, pdo);
  EXPECT_EQ(f.id, 0x203U);
  EXPECT_THAT(bytes(f), ElementsAre(0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF));
  DriveRpdo1 back;
  ASSERT_TRUE(decode_drive_rpdo1(f, back));
  EXPECT_EQ(back, pdo);
}

TEST(PdoCodec, DriveTpdosRoundTrip) {
  for (const DriveTpdo1 pdo : {DriveTpdo1{0x0237, 123456789}, DriveTpdo1{0x0008, INT32_MIN}}) {
    const CanFrame f = encode_drive_tpdo1(3, pdo);
    EXPECT_EQ(f.id, 0x183U);
    DriveTpdo1 back;
    ASSERT_TRUE(decode_drive_tpdo1(f, back));
    EXPECT_EQ(back, pdo);
  }
  const DriveTpdo2 v{-3'550'000, 8};
  const CanFrame f = encode_drive_tpdo2(3, v);
  EXPECT_EQ(f.id, 0x283U);
  EXPECT_EQ(f.dlc, 5);
  DriveTpdo2 back;
  ASSERT_TRUE(decode_drive_tpdo2(f, back));
  EXPECT_EQ(back, v);
}

TEST(PdoCodec, LoadCellInt24RoundTripAndSaturation) {
  const LoadCellTpdo1 pdo{{123'456, -1}, kLoadCellCh0Valid | kLoadCellCh1Valid, 200};
  const CanFrame f = encode_load_cell_tpdo1(4, pdo);
  EXPECT_EQ(f.id, 0x184U);
  EXPECT_THAT(bytes(f), ElementsAre(0x40, 0xE2, 0x01, 0xFF, 0xFF, 0xFF, 0x03, 200));
  LoadCellTpdo1 back;
  ASSERT_TRUE(decode_load_cell_tpdo1(f, back));
  EXPECT_EQ(back, pdo);

  const LoadCellTpdo1 huge{{100'000'000, -100'000'000}, 0, 0};
  ASSERT_TRUE(decode_load_cell_tpdo1(encode_load_cell_tpdo1(4, huge), back));
  EXPECT_EQ(back.tension_mn[0], kLoadCellTensionMaxMn);
  EXPECT_EQ(back.tension_mn[1], kLoadCellTensionMinMn);
}

TEST(PdoCodec, DecodersRejectWrongLengthAndReservedBits) {
  CanFrame f = encode_drive_tpdo1(3, {0x27, 5});
  f.dlc = 5;
  DriveTpdo1 t1;
  EXPECT_FALSE(decode_drive_tpdo1(f, t1));
  f = encode_drive_rpdo1(3, {0x0F, 5});
  f.dlc = 8;
  DriveRpdo1 r1;
  EXPECT_FALSE(decode_drive_rpdo1(f, r1));
  f = encode_load_cell_tpdo1(4, {});
  f.data[6] = 0x20;
  LoadCellTpdo1 lc;
  EXPECT_FALSE(decode_load_cell_tpdo1(f, lc));
  f = encode_drive_tpdo2(3, {});
  f.rtr = true;
  DriveTpdo2 t2;
  EXPECT_FALSE(decode_drive_tpdo2(f, t2));
}

TEST(SyncCodec, WithAndWithoutCounter) {
  std::uint8_t counter = 99;
  CanFrame f = encode_sync();
  EXPECT_EQ(f.id, 0x080U);
  EXPECT_EQ(f.dlc, 0);
  ASSERT_TRUE(decode_sync(f, counter));
  EXPECT_EQ(counter, 0);
  f = encode_sync(240);
  ASSERT_TRUE(decode_sync(f, counter));
  EXPECT_EQ(counter, 240);
  f.data[0] = 241;
  EXPECT_FALSE(decode_sync(f, counter));
  f.dlc = 2;
  EXPECT_FALSE(decode_sync(f, counter));
}

TEST(EmcyCodec, RoundTripAndText) {
  const EmcyMessage m{0x2310, kErrRegGeneric | kErrRegCurrent, {1, 2, 3, 4, 5}};
  const CanFrame f = encode_emcy(3, m);
  EXPECT_EQ(f.id, 0x083U);
  EXPECT_THAT(bytes(f), ElementsAre(0x10, 0x23, 0x03, 1, 2, 3, 4, 5));
  EmcyMessage back;
  ASSERT_TRUE(decode_emcy(f, back));
  EXPECT_EQ(back, m);
  EXPECT_STREQ(emcy_error_text(0x2310), "continuous over-current");
  EXPECT_STREQ(emcy_error_text(0x8130), "life guard or heartbeat error");
  EXPECT_STREQ(emcy_error_text(0x4321), "temperature");
  EXPECT_STREQ(emcy_error_text(0x0000), "error reset or no error");
  CanFrame short_frame = f;
  short_frame.dlc = 4;
  EXPECT_FALSE(decode_emcy(short_frame, back));
}

TEST(NmtCodec, CommandsAndHeartbeats) {
  const CanFrame f = encode_nmt(NmtCommand::start, 3);
  EXPECT_EQ(f.id, 0x000U);
  EXPECT_THAT(bytes(f), ElementsAre(0x01, 3));
  NmtCommand c{};
  std::uint8_t node = 0;
  ASSERT_TRUE(decode_nmt(f, c, node));
  EXPECT_EQ(c, NmtCommand::start);
  EXPECT_EQ(node, 3);

  const CanFrame hb = encode_heartbeat(4, NmtState::operational);
  EXPECT_EQ(hb.id, 0x704U);
  NmtState s{};
  ASSERT_TRUE(decode_nmt_state(hb.data[0], s));
  EXPECT_EQ(s, NmtState::operational);
  EXPECT_FALSE(decode_nmt_state(0x85, s));
  EXPECT_FALSE(decode_nmt_state(0x01, s));
}

TEST(SdoCodec, ExpeditedFramesRoundTrip) {
  struct Case {
    SdoMessage m;
    bool from_server;
    std::uint8_t command_byte;
  };
  const SdoAddress a{0x6060, 0};
  for (const Case& c :
       {Case{{SdoKind::download_request, a, 8, 1}, false, 0x2F},
        Case{{SdoKind::download_request, a, 0x1234, 2}, false, 0x2B},
        Case{{SdoKind::download_request, a, 0x123456, 3}, false, 0x27},
        Case{{SdoKind::download_request, a, 0xDEADBEEF, 4}, false, 0x23},
        Case{{SdoKind::download_response, a, 0, 0}, true, 0x60}, Case{{SdoKind::upload_request, a, 0, 0}, false, 0x40},
        Case{{SdoKind::upload_response, a, 0xAB, 1}, true, 0x4F},
        Case{{SdoKind::upload_response, a, 0x00020192, 4}, true, 0x43},
        Case{{SdoKind::abort, a, sdo_abort::kNoObject, 4}, true, 0x80}}) {
    const CanFrame f = encode_sdo(5, c.m);
    EXPECT_EQ(f.id, c.from_server ? 0x585U : 0x605U);
    EXPECT_EQ(f.dlc, 8);
    EXPECT_EQ(f.data[0], c.command_byte);
    SdoMessage back;
    ASSERT_TRUE(decode_sdo(f, c.from_server, back));
    EXPECT_EQ(back.kind, c.m.kind);
    EXPECT_EQ(back.address, c.m.address);
    EXPECT_EQ(back.value, c.m.value);
    EXPECT_EQ(back.size, c.m.size);
  }
}

TEST(SdoAbort, CommonCodesDecodeToText) {
  EXPECT_STREQ(sdo_abort::text(0x0504'0000), "SDO protocol timed out");
  EXPECT_STREQ(sdo_abort::text(0x0602'0000), "object does not exist in the object dictionary");
  EXPECT_STREQ(sdo_abort::text(0x0601'0002), "attempt to write a read-only object");
  EXPECT_STREQ(sdo_abort::text(0x0609'0030), "invalid value for parameter (download only)");
  EXPECT_STREQ(sdo_abort::text(0x1234'5678), "unknown SDO abort code");
}

}  // namespace
}  // namespace tensegrity::fw::canopen

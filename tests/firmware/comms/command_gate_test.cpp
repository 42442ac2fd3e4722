// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/command_gate.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {
namespace {

constexpr std::uint16_t kVersion = 2;
constexpr std::int64_t kMaxAge = 5'000'000'000;

WriterId writer(std::uint8_t tag) {
  WriterId w{};
  w[0] = tag;
  w[15] = 0x03;
  return w;
}

CommandSample command(WireCommandKind kind, std::uint32_t seq, std::uint8_t writer_tag = 1) {
  CommandSample c;
  c.writer = writer(writer_tag);
  c.format_version = kVersion;
  c.seq = seq;
  c.kind = static_cast<std::uint8_t>(kind);
  c.endcap_mask = 0x0FFF;
  c.start_host_time_ns = 10'000'000'000;
  c.issued_host_time_ns = 9'000'000'000;
  c.asked_host_time_ns = 9'000'000'000;  // read for a clear-fault only
  return c;
}

const HostClockView kSynced{true, 9'500'000'000};
const HostClockView kNotSynced{};
const EstopCount kNoEstops{};

// Judges and records as the node does; returns the decision.
GateDecision handle(CommandGate& gate, const CommandSample& c, const HostClockView& clock = kSynced) {
  const GateDecision d = gate.judge(c, clock, kNoEstops);
  if (d.verdict == GateVerdict::refuse || d.verdict == GateVerdict::deliver) gate.record(c, d.reason);
  return d;
}

TEST(CommandGate, IgnoresCommandsForOtherEndcaps) {
  CommandGate gate(3, kVersion, kMaxAge);
  CommandSample c = command(WireCommandKind::stop, 10);
  c.endcap_mask = 0x0FF7;  // all but 3
  EXPECT_EQ(gate.judge(c, kSynced, kNoEstops).verdict, GateVerdict::not_addressed);
  c.endcap_mask = 0x0008;
  EXPECT_EQ(gate.judge(c, kSynced, kNoEstops).verdict, GateVerdict::deliver);
}

TEST(CommandGate, ARetryGetsTheFirstAnswerAndIsNotActedOnAgain) {
  CommandGate gate(0, kVersion, kMaxAge);
  const CommandSample c = command(WireCommandKind::stop, 10);
  EXPECT_EQ(handle(gate, c).verdict, GateVerdict::deliver);
  const GateDecision again = gate.judge(c, kSynced, kNoEstops);
  EXPECT_EQ(again.verdict, GateVerdict::repeat);
  EXPECT_EQ(again.reason, CommandReason::accepted);
  // The same seq from another writer is another command.
  EXPECT_EQ(gate.judge(command(WireCommandKind::stop, 10, 2), kSynced, kNoEstops).verdict, GateVerdict::deliver);
}

TEST(CommandGate, RefusesOtherFormatVersionsAndUnknownKinds) {
  CommandGate gate(0, kVersion, kMaxAge);
  CommandSample c = command(WireCommandKind::stop, 1);
  c.format_version = kVersion + 1;
  EXPECT_EQ(handle(gate, c).reason, CommandReason::wrong_format_version);
  c = command(WireCommandKind::stop, 2);
  c.kind = 9;
  const GateDecision d = handle(gate, c);
  EXPECT_EQ(d.verdict, GateVerdict::refuse);
  EXPECT_EQ(d.reason, CommandReason::unknown_kind);
}

TEST(CommandGate, AnEstopIsTakenFromAnyFormatVersion) {
  CommandGate gate(0, kVersion, kMaxAge);
  for (const std::uint16_t version : {std::uint16_t{kVersion - 1}, std::uint16_t{kVersion + 1}, std::uint16_t{0}}) {
    CommandSample c = command(WireCommandKind::emergency_stop, 10U + version);
    c.format_version = version;
    const GateDecision d = handle(gate, c);
    EXPECT_EQ(d.verdict, GateVerdict::deliver) << "version " << version;
    EXPECT_EQ(d.kind, WireCommandKind::emergency_stop);
  }
  CommandSample clear = command(WireCommandKind::clear_fault, 50);
  clear.format_version = kVersion + 1;
  EXPECT_EQ(handle(gate, clear).reason, CommandReason::wrong_format_version) << "every other order is refused";
}

TEST(CommandGate, OlderSequenceFromTheSameWriterIsOutOfOrderButAnEstopAlwaysPasses) {
  CommandGate gate(0, kVersion, kMaxAge);
  EXPECT_EQ(handle(gate, command(WireCommandKind::clear_fault, 100)).verdict, GateVerdict::deliver);
  const GateDecision late_stop = handle(gate, command(WireCommandKind::stop, 99));
  EXPECT_EQ(late_stop.verdict, GateVerdict::refuse);
  EXPECT_EQ(late_stop.reason, CommandReason::out_of_order);
  const GateDecision late_estop = handle(gate, command(WireCommandKind::emergency_stop, 98));
  EXPECT_EQ(late_estop.verdict, GateVerdict::deliver);
  EXPECT_EQ(late_estop.kind, WireCommandKind::emergency_stop);
  // Newer ones pass; another writer has its own order.
  EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 101)).verdict, GateVerdict::deliver);
  EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 5, 7)).verdict, GateVerdict::deliver);
}

TEST(CommandGate, SequenceOrderSurvivesWrapAround) {
  CommandGate gate(0, kVersion, kMaxAge);
  EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 0xFFFF'FFFEU)).verdict, GateVerdict::deliver);
  EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 1)).verdict, GateVerdict::deliver);  // wrapped: newer
  EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 0xFFFF'FFFFU)).reason, CommandReason::out_of_order);
  EXPECT_TRUE(seq_newer(1, 0xFFFF'FFFFU));
  EXPECT_FALSE(seq_newer(0xFFFF'FFFFU, 1));
  EXPECT_FALSE(seq_newer(7, 7));
}

TEST(CommandGate, OnlyAStartIsJudgedByTheClock) {
  CommandGate gate(0, kVersion, kMaxAge);
  // The end cap believes host time is an hour later (a forged time sync).
  const HostClockView moved{true, 9'000'000'000 + 3'600'000'000'000};
  const GateDecision start = handle(gate, command(WireCommandKind::start, 1), moved);
  EXPECT_EQ(start.verdict, GateVerdict::refuse);
  EXPECT_EQ(start.reason, CommandReason::stale);
  for (const auto kind : {WireCommandKind::stop, WireCommandKind::emergency_stop, WireCommandKind::clear_fault}) {
    static std::uint32_t seq = 10;
    EXPECT_EQ(handle(gate, command(kind, ++seq), moved).verdict, GateVerdict::deliver) << static_cast<int>(kind);
  }
  // Before the first sync nothing is stale (the start is refused later, unsynced).
  EXPECT_EQ(gate.judge(command(WireCommandKind::start, 100), kNotSynced, kNoEstops).verdict, GateVerdict::deliver);
}

TEST(CommandGate, StartTimesOutsideTheWireRangeAreRefusedBeforeAnyArithmetic) {
  CommandGate gate(0, kVersion, kMaxAge);
  const std::int64_t bad[] = {-1, std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max(),
                              kMaxWireTimeNs + 1};
  std::uint32_t seq = 1;
  for (const std::int64_t t : bad) {
    CommandSample c = command(WireCommandKind::start, seq++);
    c.issued_host_time_ns = t;
    EXPECT_EQ(gate.judge(c, kSynced, kNoEstops).reason, CommandReason::bad_time) << t;
    c = command(WireCommandKind::start, seq++);
    c.start_host_time_ns = t;
    EXPECT_EQ(gate.judge(c, kSynced, kNoEstops).reason, CommandReason::bad_time) << t;
  }
}

TEST(CommandGate, RemembersAnswersOfManyWritersWithinItsBounds) {
  CommandGate gate(0, kVersion, kMaxAge);
  // More writers than it tracks: the oldest is forgotten, never an error.
  for (std::uint8_t w = 0; w < 40; ++w) {
    EXPECT_EQ(handle(gate, command(WireCommandKind::stop, 50, w)).verdict, GateVerdict::deliver);
  }
  EXPECT_EQ(gate.judge(command(WireCommandKind::stop, 50, 39), kSynced, kNoEstops).verdict, GateVerdict::repeat);
  EXPECT_EQ(gate.judge(command(WireCommandKind::stop, 49, 39), kSynced, kNoEstops).reason, CommandReason::out_of_order);
}

// Rule 7: a clear-fault from another writer, issued before an emergency stop it
// had not seen, must not undo it; per-writer ordering cannot tell.
TEST(CommandGate, AClearFaultThatHasNotSeenTheLatestEstopIsRefused) {
  CommandGate gate(0, kVersion, kMaxAge);
  constexpr std::uint32_t kLife = 0x5eed0001;
  CommandSample clear = command(WireCommandKind::clear_fault, 20, 1);
  clear.estops_seen = {kLife, 2};
  const GateDecision late = gate.judge(clear, kSynced, {kLife, 3});  // a third estop, from writer 2, landed first
  EXPECT_EQ(late.verdict, GateVerdict::refuse);
  EXPECT_EQ(late.reason, CommandReason::estop_unseen);
  gate.record(clear, late.reason);
  EXPECT_EQ(gate.judge(clear, kSynced, {kLife, 3}).reason, CommandReason::estop_unseen) << "a retry: same answer";
  // The sender looks again and clears with the count it now sees.
  CommandSample again = command(WireCommandKind::clear_fault, 21, 1);
  again.estops_seen = {kLife, 3};
  EXPECT_EQ(gate.judge(again, kSynced, {kLife, 3}).verdict, GateVerdict::deliver);
}

TEST(CommandGate, AClearFaultThatSawAnEarlierLifeNeverMatches) {
  CommandGate gate(0, kVersion, kMaxAge);
  CommandSample clear = command(WireCommandKind::clear_fault, 20, 1);
  clear.estops_seen = {0x5eed0001, 1};
  // The end cap restarted and took one estop in its new life: the same count.
  EXPECT_EQ(gate.judge(clear, kSynced, {0x5eed0003, 1}).reason, CommandReason::estop_unseen);
  // A tool that never heard the end cap names no life: refused, estops taken or not.
  clear.estops_seen = {};
  EXPECT_EQ(gate.judge(clear, kSynced, {0x5eed0003, 0}).reason, CommandReason::estop_unseen);
}

// Rule 7's time: a tool that first heard this end cap after another tool's estop
// names the count with that estop in it; the estop was issued after the operator
// asked, so the clear is refused all the same.
TEST(CommandGate, AClearAskedBeforeAnEstopWasIssuedIsRefusedEvenWithItsCount) {
  CommandGate gate(0, kVersion, kMaxAge);
  constexpr std::uint32_t kLife = 0x5eed0001;
  CommandSample estop = command(WireCommandKind::emergency_stop, 7, 2);
  estop.issued_host_time_ns = 9'200'000'000;
  handle(gate, estop);
  CommandSample clear = command(WireCommandKind::clear_fault, 20, 1);
  clear.estops_seen = {kLife, 1};
  clear.asked_host_time_ns = 9'100'000'000;
  EXPECT_EQ(gate.judge(clear, kSynced, {kLife, 1}).reason, CommandReason::estop_unseen);
  clear.asked_host_time_ns = 9'200'000'000;  // asked as the estop went out: it could have seen it
  EXPECT_EQ(gate.judge(clear, kSynced, {kLife, 1}).verdict, GateVerdict::deliver);
  // A re-sent estop (the same sample) keeps its first time; a later one moves it on.
  handle(gate, estop);
  CommandSample later = command(WireCommandKind::emergency_stop, 8, 2);
  later.issued_host_time_ns = 9'400'000'000;
  handle(gate, later);
  clear.asked_host_time_ns = 9'300'000'000;
  EXPECT_EQ(gate.judge(clear, kSynced, {kLife, 2}).reason, CommandReason::estop_unseen);
}

TEST(CommandGate, AClearWithoutAValidAskedTimeIsRefused) {
  CommandGate gate(0, kVersion, kMaxAge);
  CommandSample clear = command(WireCommandKind::clear_fault, 20, 1);
  for (const std::int64_t bad : {std::int64_t{-1}, kMaxWireTimeNs + 1, std::numeric_limits<std::int64_t>::min()}) {
    clear.asked_host_time_ns = bad;
    EXPECT_EQ(gate.judge(clear, kSynced, kNoEstops).reason, CommandReason::bad_time) << bad;
  }
}

// An estop is taken whatever its version or time, but only one of this version with
// a valid time says when it was issued: a foreign one must not refuse every clear
// for the rest of the end cap's life.
TEST(CommandGate, OnlyAnEstopOfThisVersionWithAValidTimeDatesTheStops) {
  CommandGate gate(0, kVersion, kMaxAge);
  CommandSample foreign = command(WireCommandKind::emergency_stop, 7, 2);
  foreign.format_version = kVersion + 1;
  foreign.issued_host_time_ns = 9'900'000'000;
  EXPECT_EQ(handle(gate, foreign).verdict, GateVerdict::deliver);
  CommandSample bad_time = command(WireCommandKind::emergency_stop, 8, 2);
  bad_time.issued_host_time_ns = -5;
  EXPECT_EQ(handle(gate, bad_time).verdict, GateVerdict::deliver);
  CommandSample clear = command(WireCommandKind::clear_fault, 20, 1);
  clear.asked_host_time_ns = 9'100'000'000;
  EXPECT_EQ(gate.judge(clear, kSynced, kNoEstops).verdict, GateVerdict::deliver);
}

TEST(CommandGate, OnlyAClearFaultIsJudgedByTheEstopsItHasSeen) {
  CommandGate gate(0, kVersion, kMaxAge);
  std::uint32_t seq = 30;
  for (const WireCommandKind kind : {WireCommandKind::start, WireCommandKind::stop, WireCommandKind::emergency_stop}) {
    const CommandSample c = command(kind, seq++);
    EXPECT_EQ(gate.judge(c, kSynced, {0x5eed0001, 7}).verdict, GateVerdict::deliver) << static_cast<int>(kind);
  }
}

}  // namespace
}  // namespace tensegrity::fw::comms

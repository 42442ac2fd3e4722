// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/start_readiness.hpp"

#include <gtest/gtest.h>

namespace tensegrity::fw::comms {
namespace {

LoopReadiness ready() { return LoopReadiness{true, core::FaultCause::none, true}; }

TEST(StartReadiness, ALoopWithDrivesUpATableAndNoFaultTakesAStart) {
  EXPECT_EQ(start_readiness(ready()), CommandReason::accepted);
}

TEST(StartReadiness, EachMissingConditionIsNamed) {
  LoopReadiness l = ready();
  l.has_table = false;
  EXPECT_EQ(start_readiness(l), CommandReason::no_table);
  l = ready();
  l.drives_enabled = false;
  EXPECT_EQ(start_readiness(l), CommandReason::drives_not_enabled);
  l = ready();
  l.fault = core::FaultCause::drive_lost;
  EXPECT_EQ(start_readiness(l), CommandReason::fault_latched);
}

// A latched fault takes the drives down with it: the operator is sent to the cause
// (clear-fault), not to the drives; the table is the last thing to look at.
TEST(StartReadiness, TheFaultIsNamedBeforeTheDrivesAndTheDrivesBeforeTheTable) {
  EXPECT_EQ(start_readiness(LoopReadiness{false, core::FaultCause::emergency_stop, false}),
            CommandReason::fault_latched);
  EXPECT_EQ(start_readiness(LoopReadiness{false, core::FaultCause::none, false}), CommandReason::drives_not_enabled);
  EXPECT_EQ(start_readiness(LoopReadiness{}), CommandReason::drives_not_enabled) << "a loop never heard from";
}

TEST(StartReadiness, EveryRefusalHasItsOwnWords) {
  for (const CommandReason r :
       {CommandReason::fault_latched, CommandReason::drives_not_enabled, CommandReason::no_table}) {
    EXPECT_STRNE(describe(r), "unknown reason");
    EXPECT_STRNE(describe(r), describe(CommandReason::accepted));
  }
  EXPECT_STRNE(describe(CommandReason::no_table), describe(CommandReason::drives_not_enabled));
}

}  // namespace
}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// What `tensegrity start` reads back after the acks: an end cap counts as playing
// only on telemetry sampled at or after the start time that shows it running.
#include "ground/start_check.hpp"

#include <gtest/gtest.h>

#include "core/fault.hpp"

namespace tensegrity::ground {
namespace {

constexpr std::int64_t kStartNs = 5'000'000'000;

EndcapStatus heard(std::int64_t at_ns, std::uint8_t mode, core::FaultCause fault, bool drives) {
  EndcapStatus s;
  s.seen = true;
  s.have_telemetry = true;
  s.telemetry_host_ns = at_ns + 2'000'000;  // arrival, a little after the sample
  s.telemetry.host_time_ns(at_ns);
  s.telemetry.mode(mode);
  s.telemetry.fault(static_cast<std::uint8_t>(fault));
  s.telemetry.drives_enabled(drives);
  return s;
}

TEST(StartCheck, OnlyTelemetryAfterTheStartTimeShowingRunningCounts) {
  std::array<EndcapStatus, kEndcapCount> status{};
  status[0] = heard(kStartNs + 10'000'000, 1, core::FaultCause::none, true);  // playing
  status[1] = heard(kStartNs - 10'000'000, 1, core::FaultCause::none, true);  // running before: an old start
  status[2] = heard(kStartNs + 10'000'000, 0, core::FaultCause::none, true);  // idle after the start time
  status[3] = heard(kStartNs + 10'000'000, 2, core::FaultCause::drive_lost, false);
  // end cap 4: never heard
  // end cap 5: running, sampled just before the start, arriving after it: not evidence
  status[5] = heard(kStartNs - 1'000'000, 1, core::FaultCause::none, true);
  const auto checks = check_playing(status, 0b111111, kStartNs);
  ASSERT_EQ(checks.size(), 6u);
  EXPECT_TRUE(checks[0].playing);
  EXPECT_FALSE(checks[1].playing);
  EXPECT_FALSE(checks[1].heard) << "a sample from before the start time says nothing about the start";
  EXPECT_FALSE(checks[2].playing);
  EXPECT_TRUE(checks[2].heard);
  EXPECT_EQ(checks[2].state, "idle");
  EXPECT_EQ(checks[3].state, "faulted, fault drive_lost, drives not enabled");
  EXPECT_FALSE(checks[4].heard);
  EXPECT_GT(status[5].telemetry_host_ns, kStartNs);
  EXPECT_FALSE(checks[5].playing) << "arrived after the start time, but sampled before it";
  EXPECT_FALSE(all_playing(checks));
  const std::string report = format_playing(checks);
  EXPECT_NE(report.find("1 of 6 end caps playing"), std::string::npos) << report;
  EXPECT_NE(report.find("end cap 2: NOT playing (idle)"), std::string::npos) << report;
  EXPECT_NE(report.find("end cap 4: NOT playing (no telemetry since the start time)"), std::string::npos) << report;
  EXPECT_EQ(report.find("end cap 0:"), std::string::npos) << "a playing end cap needs no line";
}

TEST(StartCheck, OnlyTheAddressedEndcapsAreJudged) {
  std::array<EndcapStatus, kEndcapCount> status{};
  status[7] = heard(kStartNs + 1, 1, core::FaultCause::none, true);
  const auto checks = check_playing(status, 1U << 7, kStartNs);
  ASSERT_EQ(checks.size(), 1u);
  EXPECT_EQ(checks[0].endcap, 7);
  EXPECT_TRUE(all_playing(checks));
  EXPECT_EQ(format_playing(checks), "1 of 1 end caps playing\n");
}

}  // namespace
}  // namespace tensegrity::ground

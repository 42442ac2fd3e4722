// SPDX-License-Identifier: Apache-2.0
// The tick source on a fake clock, without processes or sockets: the lockstep
// barrier's release and its timeout naming the missing end cap; real-time pacing
// to absolute deadlines and the late-step count; a stop ending every wait.
#include <gtest/gtest.h>

#include <set>

#include "hil/hil_error.hpp"
#include "hil/tick_source.hpp"
#include "hil_fakes.hpp"

namespace tensegrity::hil {
namespace {

using hil_test::FakeClock;

constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr std::int64_t kAnswerNs = 50'000;

// End caps `expected` answer one per receive(), kAnswerNs apart; `silent` never do.
class FakeAnswers final : public TickAnswers {
 public:
  FakeAnswers(FakeClock& clock, std::set<int> expected, std::set<int> silent)
      : clock_(clock), waiting_(std::move(expected)), silent_(std::move(silent)) {}
  bool all_in() const override { return waiting_.empty(); }
  bool receive(std::int64_t deadline_ns) override {
    ++receives;
    for (int e : waiting_) {
      if (silent_.count(e)) continue;
      clock_.now = std::min(deadline_ns, clock_.now + kAnswerNs);
      waiting_.erase(e);
      arrival_ = clock_.now;
      return true;
    }
    clock_.now = std::max(clock_.now, deadline_ns);  // nothing comes: the wait runs out
    return false;
  }
  void forget_arrivals() override { arrival_ = 0; }
  std::int64_t latest_arrival_ns() const override { return arrival_; }
  std::string missing() override {
    std::string m;
    for (int e : waiting_) m += " end cap " + std::to_string(e) + " sent nothing;";
    return m;
  }
  int receives = 0;

 private:
  FakeClock& clock_;
  std::set<int> waiting_;
  std::set<int> silent_;
  std::int64_t arrival_ = 0;
};

std::string barrier_error(TickSource& source, TickAnswers& answers, std::int64_t step) {
  try {
    source.barrier(answers, TickSource::Expect::usual, 2'000'000'000, 12, step);
  } catch (const HilError& e) {
    return e.what();
  }
  return "released";
}

TEST(HilTickSource, LockstepReleasesWhenEveryAnswerIsIn) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  FakeAnswers answers(clock, {0, 3, 7}, {});
  const std::int64_t waited = source.barrier(answers, TickSource::Expect::usual, 2'000'000'000, 1, 0);
  EXPECT_TRUE(answers.all_in());
  EXPECT_EQ(answers.receives, 3) << "no wait after the last answer";
  EXPECT_EQ(waited, 3 * kAnswerNs);
}

TEST(HilTickSource, LockstepWithNobodyExpectedDoesNotWait) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.7);
  FakeAnswers answers(clock, {}, {});
  EXPECT_EQ(source.barrier(answers, TickSource::Expect::nothing, 2'000'000'000, 1, 0), 0);
  EXPECT_EQ(answers.receives, 0);
  EXPECT_EQ(clock.sleeps, 0) << "no nap either";
}

TEST(HilTickSource, LockstepNapsAFractionOfTheUsualAnswerTime) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.5);
  FakeAnswers first(clock, {0, 1}, {});
  source.barrier(first, TickSource::Expect::usual, 2'000'000'000, 1, 0);  // learns 100 us
  EXPECT_EQ(clock.sleeps, 1);
  const std::int64_t before = clock.now;
  FakeAnswers second(clock, {0, 1}, {});
  source.barrier(second, TickSource::Expect::usual, 2'000'000'000, 2, 1);
  EXPECT_EQ(clock.now - before, 50'000 + 2 * kAnswerNs) << "a 50 us nap (half of 100 us), then the answers";
  FakeAnswers third(clock, {0}, {});
  const int sleeps = clock.sleeps;
  source.barrier(third, TickSource::Expect::first_answers, 2'000'000'000, 3, 2);
  EXPECT_EQ(clock.sleeps, sleeps) << "no nap for a just-started program's first answer";
}

TEST(HilTickSource, LockstepTimeoutNamesTheMissingEndCapAndTheTick) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  FakeAnswers answers(clock, {2, 9, 11}, {9});
  const std::int64_t t0 = clock.now;
  const std::string why = barrier_error(source, answers, 3);
  EXPECT_NE(why.find("no drive targets within 2 s of the SYNC of tick 12 (physics step 3):"), std::string::npos) << why;
  EXPECT_NE(why.find("end cap 9 sent nothing"), std::string::npos) << why;
  EXPECT_EQ(why.find("end cap 2"), std::string::npos) << why;
  EXPECT_EQ(why.find("end cap 11"), std::string::npos) << why;
  EXPECT_EQ(clock.now - t0, 2'000'000'000) << "it waited the whole timeout";
  FakeAnswers booting(clock, {4}, {4});
  EXPECT_NE(barrier_error(source, booting, -1).find("tick 12 (boot):"), std::string::npos);
}

TEST(HilTickSource, RealTimePacesToAbsoluteDeadlinesAndCountsLateSteps) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  // The host wakes the stepper on time except: a 3 ms stall before step 10
  // (steps 10, 11, 12 then begin 3, 2 and 1 ms late: one episode), 0.7 ms at
  // step 50 (late: more than half a period) and 0.3 ms at step 70 (not late).
  clock.wake_late = [&](int sleep) -> std::int64_t {
    if (sleep == 11) return 3'000'000;
    if (sleep == 51) return 700'000;
    if (sleep == 71) return 300'000;
    return 0;
  };
  const std::int64_t origin = clock.now + kPeriodNs;
  source.start_pacing(origin);
  std::vector<std::int64_t> late;
  for (std::int64_t k = 0; k < 100; ++k) late.push_back(source.pace(k, 50'000));
  EXPECT_EQ(late[10], 3'000'000);
  EXPECT_EQ(late[11], 2'000'000) << "deadlines do not move after a stall";
  EXPECT_EQ(late[12], 1'000'000);
  EXPECT_EQ(late[13], 0);
  const LatenessSummary s = source.lateness();
  EXPECT_EQ(s.steps, 100);
  EXPECT_EQ(s.late_steps, 4);
  EXPECT_EQ(s.late_episodes, 2);
  EXPECT_EQ(s.missed_steps, 3);
  EXPECT_EQ(s.max_ns, 3'000'000);
  EXPECT_EQ(clock.now, origin + 99 * kPeriodNs);
}

TEST(HilTickSource, PeriodsBetweenRunsSkipOrCatchUpMissedOnes) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  source.begin_periods(clock.now);
  clock.now += 5 * kPeriodNs + 1;  // a stall
  source.advance_period(false);
  EXPECT_EQ(source.period_end_ns(), clock.now - 5 * kPeriodNs - 1 + kPeriodNs) << "real time: caught up one by one";
  source.advance_period(true);
  EXPECT_EQ(source.period_end_ns(), clock.now) << "lockstep: no burst of ticks to make up the stall";
}

TEST(HilTickSource, LockstepWithoutASpeedLimitNeverSleeps) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  source.limit_speed(0.0);
  for (int k = 0; k < 10; ++k) source.pace_lockstep();
  EXPECT_EQ(clock.sleeps, 0);
}

TEST(HilTickSource, LockstepSpeedLimitKeepsPhysicsToTheFactor) {
  for (const double speed : {1.0, 2.0, 0.5}) {
    FakeClock clock;
    TickSource source(clock, kPeriodNs, {}, 0.0);
    source.limit_speed(speed);
    const std::int64_t t0 = clock.now;
    for (int k = 0; k < 1000; ++k) {
      source.pace_lockstep();
      clock.now += 100'000;  // the tick itself: 0.1 ms of work
    }
    // 1000 ticks begin (1000 - 1) tick periods apart and the last takes 0.1 ms.
    const auto tick_ns = static_cast<std::int64_t>(static_cast<double>(kPeriodNs) / speed);
    EXPECT_EQ(clock.now - t0, 999 * tick_ns + 100'000) << "speed " << speed;
  }
}

TEST(HilTickSource, LockstepSpeedLimitCatchesUpAStallOnlyPartly) {
  FakeClock clock;
  TickSource source(clock, kPeriodNs, {}, 0.0);
  source.limit_speed(1.0);
  source.pace_lockstep();
  clock.now += 1'000'000'000;  // a tick that took 1 s (a stalled end cap)
  int at_once = 0;
  for (int k = 0; k < 1000; ++k) {
    const int sleeps = clock.sleeps;
    const std::int64_t before = clock.now;
    source.pace_lockstep();
    if (clock.now == before && (clock.sleeps == sleeps + 1)) ++at_once;
    clock.now += 1000;
  }
  // At most kSpeedCatchUpNs of physics without a wait (the last tick at the limit's
  // pace included), not the whole second.
  const auto catch_up_ticks = static_cast<int>(TickSource::kSpeedCatchUpNs / kPeriodNs);
  EXPECT_GE(at_once, catch_up_ticks - 1);
  EXPECT_LE(at_once, catch_up_ticks + 2);
}

TEST(HilTickSource, AStopEndsEveryWait) {
  FakeClock clock;
  std::stop_source stop;
  TickSource source(clock, kPeriodNs, stop.get_token(), 0.0);
  EXPECT_NO_THROW(source.check_stop());
  source.start_pacing(clock.now);
  EXPECT_NO_THROW(source.pace(0, 0));
  stop.request_stop();
  EXPECT_THROW(source.check_stop(), HilError);
  try {
    source.pace(1, 0);
    FAIL() << "pace() after a stop";
  } catch (const HilError& e) {
    EXPECT_STREQ(e.what(), "interrupted");
  }
}

}  // namespace
}  // namespace tensegrity::hil

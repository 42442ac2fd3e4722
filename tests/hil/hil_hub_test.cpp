// SPDX-License-Identifier: Apache-2.0
// The emulator's hub towards end-cap buses: it answers each end cap in the
// datagram version that end cap speaks (one datagram per flush once it has sent
// version 2), keeps frame faults per frame, and stamps arrivals; and the
// real-time lateness count and the lockstep answer nap.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "firmware/drivers/cob_id.hpp"
#include "firmware/hal/udp_can_bus.hpp"
#include "hil/answer_nap.hpp"
#include "hil/clock.hpp"
#include "hil/hil_error.hpp"
#include "hil/lateness.hpp"
#include "hil/process_launcher.hpp"
#include "hil/timer_probe.hpp"
#include "hil/udp_hub.hpp"

namespace tensegrity::hil {
namespace {

constexpr std::int64_t kWaitNs = 500'000'000;

struct Rig {
  UdpHub hub{2};
  std::unique_ptr<fw::UdpCanBus> endcap[2];
  explicit Rig(bool batch0, bool batch1 = false) {
    std::string error;
    const bool batch[2] = {batch0, batch1};
    for (int e = 0; e < 2; ++e) {
      endcap[e] = fw::UdpCanBus::open(
          {fw::UdpEndpoint{"127.0.0.1", hub.port()}, fw::UdpEndpoint{"127.0.0.1", 0}, batch[e]}, error);
      EXPECT_TRUE(endcap[e]) << error;
      hub.set_endcap_port(e, endcap[e]->local_port());
    }
  }
  // The hub's view of what arrives, waiting up to kWaitNs for it.
  std::vector<UdpHub::Rx> receive(std::size_t at_least) {
    std::vector<UdpHub::Rx> rx;
    const std::int64_t deadline = monotonic_ns() + kWaitNs;
    while (rx.size() < at_least && monotonic_ns() < deadline) hub.receive(rx, deadline);
    return rx;
  }
};

fw::CanFrame frame(std::uint32_t id, std::uint8_t dlc = 6) {
  fw::CanFrame f;
  f.id = id;
  f.dlc = dlc;
  return f;
}

fw::CanFrame sync() { return frame(fw::canopen::kSyncCobId, 0); }

void queue_tick(UdpHub& hub, int e) {
  hub.queue(e, frame(0x181));
  hub.queue(e, frame(0x281, 5));
  hub.queue(e, sync());
}

std::vector<std::uint32_t> drain(fw::UdpCanBus& bus) {
  std::vector<std::uint32_t> ids;
  fw::CanFrame f;
  while (bus.receive(f, ids.empty() ? kWaitNs : 20'000'000) == fw::CanResult::ok) ids.push_back(f.id);
  return ids;
}

TEST(UdpHub, AnswersInVersionTwoOnlyAfterTheEndCapSpokeIt) {
  Rig rig(true, false);
  // Nothing heard yet: version 1, a datagram per frame.
  queue_tick(rig.hub, 0);
  rig.hub.flush();
  EXPECT_EQ(drain(*rig.endcap[0]), (std::vector<std::uint32_t>{0x181, 0x281, 0x080}));
  EXPECT_EQ(rig.hub.counters(0).tx_datagrams, 3U);

  // End cap 0 batches (two RPDO1s in one datagram), end cap 1 does not.
  for (int e = 0; e < 2; ++e) {
    rig.endcap[e]->send(frame(0x201));
    rig.endcap[e]->send(frame(0x203));
    rig.endcap[e]->flush();
  }
  const auto rx = rig.receive(4);
  ASSERT_EQ(rx.size(), 4U);
  EXPECT_TRUE(rig.hub.batches(0));
  EXPECT_FALSE(rig.hub.batches(1));
  EXPECT_EQ(rig.hub.counters(0).rx_datagrams, 1U);
  EXPECT_EQ(rig.hub.counters(1).rx_datagrams, 2U);
  EXPECT_EQ(rig.hub.counters(0).rx_frames, 2U);

  for (int e = 0; e < 2; ++e) queue_tick(rig.hub, e);
  rig.hub.flush();
  EXPECT_EQ(drain(*rig.endcap[0]), (std::vector<std::uint32_t>{0x181, 0x281, 0x080}));
  EXPECT_EQ(drain(*rig.endcap[1]), (std::vector<std::uint32_t>{0x181, 0x281, 0x080}));
  EXPECT_EQ(rig.hub.counters(0).tx_datagrams, 3U + 1U) << "one datagram for the whole tick";
  EXPECT_EQ(rig.hub.counters(1).tx_datagrams, 3U);
  EXPECT_EQ(rig.hub.counters(0).tx_frames, 6U);

  // A restarted program may be an older one: back to version 1 until it batches.
  rig.hub.forget_version(0);
  queue_tick(rig.hub, 0);
  rig.hub.flush();
  EXPECT_EQ(rig.hub.counters(0).tx_datagrams, 4U + 3U);
}

TEST(UdpHub, ABrokenDatagramTravelsAloneAndSyncStillArrives) {
  Rig rig(true);
  rig.endcap[0]->send(frame(0x201));
  rig.endcap[0]->flush();
  ASSERT_EQ(rig.receive(1).size(), 1U);
  rig.hub.set_corrupt(0, 1.0, CorruptKind::datagram);
  queue_tick(rig.hub, 0);
  rig.hub.flush();
  // The two PDOs went out as version-1 datagrams with a bad magic; SYNC is never
  // corrupted and arrives in the batch.
  EXPECT_EQ(drain(*rig.endcap[0]), (std::vector<std::uint32_t>{0x080}));
  EXPECT_EQ(rig.endcap[0]->dropped(fw::udp_can::Decoded::bad_magic), 2U);
  EXPECT_EQ(rig.hub.counters(0).injected_corrupt, 2U);
}

TEST(UdpHub, MoreThanABatchOfFramesStaysInOrder) {
  Rig rig(true);
  rig.endcap[0]->send(frame(0x201));
  rig.endcap[0]->flush();
  ASSERT_EQ(rig.receive(1).size(), 1U);
  std::vector<std::uint32_t> sent;
  for (std::uint32_t i = 0; i < 100; ++i) {
    rig.hub.queue(0, frame(0x100 + i, 1));
    sent.push_back(0x100 + i);
  }
  rig.hub.flush();
  EXPECT_EQ(drain(*rig.endcap[0]), sent);
  EXPECT_EQ(rig.hub.counters(0).tx_datagrams, 2U);
}

TEST(UdpHub, StampsWhenTheLatestDatagramArrived) {
  Rig rig(true);
  rig.hub.reset_latest_arrival();
  EXPECT_EQ(rig.hub.latest_arrival_ns(), 0);
  const std::int64_t before = monotonic_ns();
  rig.endcap[0]->send(frame(0x201));
  rig.endcap[0]->flush();
  ASSERT_EQ(rig.receive(1).size(), 1U);
  const std::int64_t after = monotonic_ns();
  // The kernel's stamp lies between the send and the read (a little slack for
  // the two clocks being read a few hundred ns apart).
  EXPECT_GE(rig.hub.latest_arrival_ns(), before - 100'000);
  EXPECT_LE(rig.hub.latest_arrival_ns(), after + 100'000);
}

TEST(Lateness, CountsLateStepsEpisodesAndMisses) {
  LatenessStats s(1'000'000, 500'000);
  for (int i = 0; i < 990; ++i) s.add(20'000);
  // One stall of 2.2 ms: the next steps run back to back until on time again.
  EXPECT_TRUE(s.add(2'200'000));
  EXPECT_TRUE(s.add(1'250'000));
  EXPECT_FALSE(s.add(300'000));
  EXPECT_FALSE(s.add(-5'000)) << "early counts as on time";
  EXPECT_TRUE(s.add(600'000));
  for (int i = 0; i < 5; ++i) s.add(20'000);
  const LatenessSummary r = s.summary();
  EXPECT_EQ(r.steps, 1000);
  EXPECT_EQ(r.late_steps, 3);
  EXPECT_EQ(r.late_episodes, 2);
  EXPECT_EQ(r.missed_steps, 2);
  EXPECT_EQ(r.max_ns, 2'200'000);
  EXPECT_EQ(r.stalled_ns, 2'200'000 + 600'000) << "each episode counts its first step";
  EXPECT_EQ(r.p50_ns, 30'000) << "upper edge of the 10 us bucket";
  EXPECT_GE(r.p999_ns, 1'250'000);
}

TEST(LauncherPorts, DistinctFreeAndBelowTheEphemeralRange) {
  std::ifstream range("/proc/sys/net/ipv4/ip_local_port_range");
  int ephemeral_low = 32768;
  range >> ephemeral_low;
  const std::vector<std::uint16_t> ports = free_udp_ports(12);
  ASSERT_EQ(ports.size(), 12U);
  EXPECT_EQ(std::set<std::uint16_t>(ports.begin(), ports.end()).size(), 12U);
  for (const std::uint16_t p : ports) {
    EXPECT_LT(p, ephemeral_low) << "a port there can be handed to any socket binding port 0";
    EXPECT_GE(p, ephemeral_low - kLauncherPortSpan);
  }
  // Released: an end cap can bind every one of them.
  std::vector<std::unique_ptr<fw::UdpCanBus>> buses;
  for (const std::uint16_t p : ports) {
    std::string error;
    buses.push_back(
        fw::UdpCanBus::open({fw::UdpEndpoint{"127.0.0.1", 9}, fw::UdpEndpoint{"127.0.0.1", p}, false}, error));
    EXPECT_NE(buses.back(), nullptr) << p << ": " << error;
  }
}

TEST(TimerProbe, PacesEveryDeadlineAndNeverReturnsEarly) {
  const std::int64_t t0 = monotonic_ns();
  const TimerProbeResult r = probe_timer_latency(0.05, 1'000'000, 50'000);
  const std::int64_t elapsed = monotonic_ns() - t0;
  EXPECT_EQ(r.lateness.steps, 50);
  // Absolute deadlines from one period after the start: 50 of them end after 50 ms.
  EXPECT_GE(elapsed, 50'000'000);
  EXPECT_LE(r.lateness.late_steps, r.lateness.steps);
  EXPECT_LE(r.lateness.late_episodes, r.lateness.late_steps);
  EXPECT_GE(r.lateness.max_ns, 0) << "the spin never ends before the deadline";
}

TEST(AnswerNap, FollowsTheUsualLatencyAndShrugsOffOneSlowTick) {
  AnswerNap nap(0.7);
  EXPECT_EQ(nap.nap_ns(), 0) << "no nap before the first answer";
  for (int i = 0; i < 200; ++i) nap.observe(100'000);
  EXPECT_NEAR(static_cast<double>(nap.nap_ns()), 70'000.0, 1'000.0);
  nap.observe(50'000'000);  // a preempted end cap
  EXPECT_LT(nap.nap_ns(), 80'000);
  EXPECT_LE(AnswerNap(0.7).nap_ns(), AnswerNap::kMaxNapNs);
  AnswerNap off(0.0);
  off.observe(100'000);
  EXPECT_EQ(off.nap_ns(), 0);
}

}  // namespace
}  // namespace tensegrity::hil

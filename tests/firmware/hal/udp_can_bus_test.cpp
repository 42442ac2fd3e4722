// SPDX-License-Identifier: Apache-2.0
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <optional>
#include <vector>

#include "firmware/hal/can_error.hpp"
#include "firmware/hal/clock.hpp"
#include "firmware/hal/can_bus_spec.hpp"
#include "firmware/hal/udp_can_bus.hpp"
#include "firmware/hal/udp_can_wire.hpp"

namespace tensegrity::fw {
namespace {

constexpr std::int64_t kWaitNs = 500'000'000;  // generous: loopback delivers in microseconds

CanFrame make_frame(std::uint32_t id, std::uint8_t dlc, std::uint8_t seed) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  for (std::uint8_t i = 0; i < dlc; ++i) f.data[i] = static_cast<std::uint8_t>(seed + i);
  return f;
}

// Two buses on loopback pointing at each other; ports picked by the kernel.
struct Pair {
  std::unique_ptr<UdpCanBus> a;
  std::unique_ptr<UdpCanBus> b;
};

Pair make_pair() {
  std::string error;
  Pair p;
  p.a = UdpCanBus::open({UdpEndpoint{"127.0.0.1", 0}, UdpEndpoint{"127.0.0.1", 0}}, error);
  EXPECT_TRUE(p.a) << error;
  p.b = UdpCanBus::open({UdpEndpoint{"127.0.0.1", p.a->local_port()}, UdpEndpoint{"127.0.0.1", 0}}, error);
  EXPECT_TRUE(p.b) << error;
  EXPECT_TRUE(p.a->set_remote({"127.0.0.1", p.b->local_port()}, error)) << error;
  return p;
}

// Sends raw bytes to a bus from a socket of its own on loopback, as a
// misbehaving peer (once made the bus's remote) or a stranger would.
class RawSender {
 public:
  explicit RawSender(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&local), sizeof(local)), 0);
    socklen_t len = sizeof(local);
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&local), &len);
    port_ = ntohs(local.sin_port);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~RawSender() { ::close(fd_); }
  std::uint16_t port() const { return port_; }
  void send(const std::vector<std::uint8_t>& bytes) { send_to(to_, bytes); }
  void send_to(const sockaddr_in& to, const std::vector<std::uint8_t>& bytes) {
    ASSERT_EQ(::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to)),
              static_cast<ssize_t>(bytes.size()));
  }

 private:
  int fd_;
  std::uint16_t port_ = 0;
  sockaddr_in to_{};
};

// b takes `raw` as its peer.
void listen_to(UdpCanBus& b, const RawSender& raw) {
  std::string error;
  ASSERT_TRUE(b.set_remote({"127.0.0.1", raw.port()}, error)) << error;
}

std::vector<std::uint8_t> valid_bytes(const CanFrame& f) {
  const udp_can::Datagram d = udp_can::encode(f);
  return {d.begin(), d.end()};
}

TEST(UdpCanWire, RoundTripsStandardExtendedAndRtrFrames) {
  CanFrame ext = make_frame(0x1234'5678, 8, 1);
  ext.extended = true;
  CanFrame rtr = make_frame(0x701, 0, 0);
  rtr.rtr = true;
  rtr.dlc = 1;
  for (const CanFrame& f : {make_frame(0x181, 6, 10), make_frame(0x7FF, 0, 0), ext, rtr}) {
    CanFrame got;
    const udp_can::Datagram d = udp_can::encode(f);
    ASSERT_EQ(udp_can::decode(d, got), udp_can::Decoded::frame);
    EXPECT_EQ(got, f);
  }
}

TEST(UdpCanBus, FramesTravelBothWays) {
  Pair p = make_pair();
  const CanFrame to_b = make_frame(0x201, 6, 1);
  const CanFrame to_a = make_frame(0x181, 8, 50);
  ASSERT_EQ(p.a->send(to_b), CanResult::ok);
  ASSERT_EQ(p.b->send(to_a), CanResult::ok);
  CanFrame got;
  ASSERT_EQ(p.b->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, to_b);
  ASSERT_EQ(p.a->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, to_a);
  EXPECT_EQ(p.a->counters().tx_frames, 1U);
  EXPECT_EQ(p.a->counters().rx_frames, 1U);
}

TEST(UdpCanBus, QueuedFramesComeOutOneAtATimeInOrder) {
  Pair p = make_pair();
  for (std::uint8_t i = 0; i < 20; ++i) ASSERT_EQ(p.a->send(make_frame(0x100U + i, 1, i)), CanResult::ok);
  for (std::uint8_t i = 0; i < 20; ++i) {
    CanFrame got;
    ASSERT_EQ(p.b->receive(got, kWaitNs), CanResult::ok);
    EXPECT_EQ(got.id, 0x100U + i);
  }
  CanFrame got;
  EXPECT_EQ(p.b->receive(got, 0), CanResult::timeout);
}

TEST(UdpCanBus, ReceiveTimesOutNonBlockingAndBounded) {
  Pair p = make_pair();
  CanFrame got;
  EXPECT_EQ(p.b->receive(got, 0), CanResult::timeout);
  SystemClock clock;
  const std::int64_t start_ns = clock.now_ns();
  EXPECT_EQ(p.b->receive(got, 3'000'000), CanResult::timeout);
  const std::int64_t waited_ns = clock.now_ns() - start_ns;
  EXPECT_GE(waited_ns, 3'000'000);
  EXPECT_LT(waited_ns, 200'000'000);
}

TEST(UdpCanBus, MalformedDatagramsAreDroppedAndCountedByReason) {
  Pair p = make_pair();
  RawSender raw(p.b->local_port());
  listen_to(*p.b, raw);
  const std::vector<std::uint8_t> good = valid_bytes(make_frame(0x181, 6, 3));

  std::vector<std::uint8_t> too_short(good.begin(), good.end() - 1);
  std::vector<std::uint8_t> too_long = good;
  too_long.push_back(0);
  std::vector<std::uint8_t> bad_magic = good;
  bad_magic[0] = 'X';
  std::vector<std::uint8_t> bad_version = good;
  bad_version[4] = 3;  // 1 and 2 exist (udp_can_batch.hpp)
  std::vector<std::uint8_t> dlc9 = good;
  dlc9[6] = 9;
  std::vector<std::uint8_t> id_too_big = good;
  id_too_big[9] = 0x08;  // 0x881 > 0x7FF with the extended flag clear
  std::vector<std::uint8_t> bad_flags = good;
  bad_flags[5] = 0x80;
  std::vector<std::uint8_t> reserved = good;
  reserved[7] = 1;

  for (const auto* bytes :
       {&too_short, &too_long, &bad_magic, &bad_version, &dlc9, &id_too_big, &bad_flags, &reserved}) {
    raw.send(*bytes);
  }
  raw.send({});  // empty datagram
  raw.send(good);

  CanFrame got;
  ASSERT_EQ(p.b->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, make_frame(0x181, 6, 3)) << "only the good datagram comes through";
  EXPECT_EQ(p.b->receive(got, 0), CanResult::timeout);

  using udp_can::Decoded;
  EXPECT_EQ(p.b->dropped(Decoded::bad_size), 3U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_magic), 1U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_version), 1U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_dlc), 1U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_id), 1U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_flags), 1U);
  EXPECT_EQ(p.b->dropped(Decoded::bad_reserved), 1U);
  EXPECT_EQ(p.b->counters().rx_malformed, 9U);
  EXPECT_EQ(p.b->counters().rx_frames, 1U);
}

TEST(UdpCanBus, BusOffReportBlocksSendingUntilRestart) {
  Pair p = make_pair();
  RawSender raw(p.b->local_port());
  listen_to(*p.b, raw);
  const udp_can::Datagram off = udp_can::encode_error_report(can_error::kBusOff, {});
  raw.send({off.begin(), off.end()});
  CanFrame got;
  EXPECT_EQ(p.b->receive(got, 20'000'000), CanResult::timeout) << "error reports are not frames";
  EXPECT_TRUE(p.b->counters().bus_off);
  EXPECT_EQ(p.b->counters().error_frames, 1U);
  EXPECT_EQ(p.b->send(make_frame(0x201, 1, 0)), CanResult::bus_off);

  const udp_can::Datagram restarted = udp_can::encode_error_report(can_error::kRestarted, {});
  raw.send({restarted.begin(), restarted.end()});
  EXPECT_EQ(p.b->receive(got, 20'000'000), CanResult::timeout);
  EXPECT_FALSE(p.b->counters().bus_off);
  EXPECT_EQ(p.b->send(make_frame(0x201, 1, 0)), CanResult::ok);
}

TEST(UdpCanBus, RefusesToSendInvalidFrames) {
  Pair p = make_pair();
  CanFrame f = make_frame(0x800, 1, 0);
  EXPECT_EQ(p.a->send(f), CanResult::invalid_frame);
  f.id = 0x100;
  f.dlc = 9;
  EXPECT_EQ(p.a->send(f), CanResult::invalid_frame);
  EXPECT_EQ(p.a->counters().tx_dropped, 2U);
}

TEST(UdpCanBus, SendWithoutRemoteIsAnError) {
  std::string error;
  auto bus = UdpCanBus::open({UdpEndpoint{"127.0.0.1", 0}, UdpEndpoint{"127.0.0.1", 0}}, error);
  ASSERT_TRUE(bus) << error;
  EXPECT_EQ(bus->send(make_frame(0x1, 0, 0)), CanResult::io_error);
}

// Whoever can put a frame on the bus can fake a drive's position or a tension:
// only the peer's datagrams count. Before a remote is set there is no peer.
TEST(UdpCanBus, DatagramsFromAnyoneButThePeerAreDroppedAndCounted) {
  Pair p = make_pair();
  RawSender stranger(p.b->local_port());
  const CanFrame forged = make_frame(0x181, 6, 9);
  stranger.send(valid_bytes(forged));
  ASSERT_EQ(p.a->send(make_frame(0x182, 6, 1)), CanResult::ok);
  CanFrame got;
  ASSERT_EQ(p.b->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, make_frame(0x182, 6, 1)) << "the stranger's frame came through";
  EXPECT_EQ(p.b->receive(got, 0), CanResult::timeout);
  EXPECT_EQ(p.b->counters().rx_unknown_sender, 1U);
  EXPECT_EQ(p.b->counters().rx_frames, 1U);

  std::string error;
  auto lone = UdpCanBus::open({UdpEndpoint{"127.0.0.1", 0}, UdpEndpoint{"127.0.0.1", 0}}, error);
  ASSERT_TRUE(lone) << error;
  RawSender to_lone(lone->local_port());
  to_lone.send(valid_bytes(forged));
  EXPECT_EQ(lone->receive(got, 50'000'000), CanResult::timeout);
  EXPECT_EQ(lone->counters().rx_unknown_sender, 1U);
}

// The first non-loopback IPv4 address of this machine, if any.
std::optional<in_addr> outside_address() {
  ifaddrs* all = nullptr;
  if (::getifaddrs(&all) != 0) return std::nullopt;
  std::optional<in_addr> found;
  for (ifaddrs* i = all; i != nullptr && !found; i = i->ifa_next) {
    if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET) continue;
    const in_addr a = reinterpret_cast<const sockaddr_in*>(i->ifa_addr)->sin_addr;
    if ((ntohl(a.s_addr) >> 24) != 127) found = a;
  }
  ::freeifaddrs(all);
  return found;
}

TEST(UdpCanBus, BindsLoopbackUnlessTold) {
  CanBusSpec spec;
  std::string error;
  ASSERT_TRUE(parse_can_bus_spec("udp:127.0.0.1:7000", spec, error)) << error;
  auto bus = UdpCanBus::open({spec.remote, spec.bind}, error);
  ASSERT_TRUE(bus) << error;
  const std::optional<in_addr> outside = outside_address();
  if (!outside) GTEST_SKIP() << "no address but loopback here";
  // The peer itself, sending to this machine's outside address: only the bind
  // stands between it and the bus.
  RawSender peer(bus->local_port());
  listen_to(*bus, peer);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr = *outside;
  to.sin_port = htons(bus->local_port());
  peer.send_to(to, valid_bytes(make_frame(0x181, 6, 2)));
  CanFrame got;
  EXPECT_EQ(bus->receive(got, 100'000'000), CanResult::timeout) << "a frame reached the bus off loopback";
  peer.send(valid_bytes(make_frame(0x182, 6, 2)));
  ASSERT_EQ(bus->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got.id, 0x182U);
}

TEST(UdpCanBus, ARemoteOffLoopbackNeedsABindAddressFacingIt) {
  std::string error;
  EXPECT_FALSE(UdpCanBus::open({UdpEndpoint{"192.0.2.1", 7000}, UdpEndpoint{}}, error));
  EXPECT_NE(error.find("bind="), std::string::npos) << error;
  auto bus = UdpCanBus::open({UdpEndpoint{"127.0.0.1", 0}, UdpEndpoint{}}, error);
  ASSERT_TRUE(bus) << error;
  EXPECT_FALSE(bus->set_remote({"192.0.2.1", 7000}, error));
  EXPECT_NE(error.find("bind="), std::string::npos) << error;
}

}  // namespace
}  // namespace tensegrity::fw

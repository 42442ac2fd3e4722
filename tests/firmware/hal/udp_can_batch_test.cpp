// SPDX-License-Identifier: Apache-2.0
// Version 2 of CAN over UDP (several frames a datagram) and the UDP bus's batch
// mode: the documented byte layout, what a receiver drops, and that a batching
// bus and a version-1 peer still understand each other.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <vector>

#include "firmware/hal/can_error.hpp"
#include "firmware/hal/udp_can_batch.hpp"
#include "firmware/hal/udp_can_bus.hpp"

namespace tensegrity::fw {
namespace {

using udp_can::BatchWriter;
using udp_can::DatagramReader;
using udp_can::Decoded;

constexpr std::int64_t kWaitNs = 500'000'000;

CanFrame make_frame(std::uint32_t id, std::uint8_t dlc, std::uint8_t seed) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  for (std::uint8_t i = 0; i < dlc; ++i) f.data[i] = static_cast<std::uint8_t>(seed + i);
  return f;
}

std::vector<std::uint8_t> bytes_of(const BatchWriter& w) { return {w.bytes().begin(), w.bytes().end()}; }

std::unique_ptr<UdpCanBus> open_bus(std::uint16_t remote_port, bool batch) {
  std::string error;
  auto bus = UdpCanBus::open({UdpEndpoint{"127.0.0.1", remote_port}, UdpEndpoint{"127.0.0.1", 0}, batch}, error);
  EXPECT_TRUE(bus) << error;
  return bus;
}

// A plain socket: sees datagrams exactly as they travel.
class RawPeer {
 public:
  RawPeer() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    timeval tv{0, 500'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~RawPeer() { ::close(fd_); }
  std::uint16_t port() const { return port_; }
  std::vector<std::uint8_t> receive() {
    std::vector<std::uint8_t> b(2048);
    const ssize_t n = ::recv(fd_, b.data(), b.size(), 0);
    b.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return b;
  }
  bool nothing_queued() {
    std::uint8_t b[1];
    return ::recv(fd_, b, sizeof b, MSG_DONTWAIT) < 0;
  }
  void send_to(std::uint16_t port, const std::vector<std::uint8_t>& bytes) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to),
              static_cast<ssize_t>(bytes.size()));
  }

 private:
  int fd_;
  std::uint16_t port_ = 0;
};

TEST(UdpCanBatch, ByteLayoutIsAsDocumented) {
  // docs/design/udp-can.md's example: drive 3's RPDO1 (controlword 0x000F, target 1000), SYNC.
  CanFrame rpdo = make_frame(0x203, 6, 0);
  rpdo.data = {0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00, 0xAA, 0xAA};  // bytes past dlc are not sent
  CanFrame sync;
  sync.id = 0x080;
  BatchWriter w;
  ASSERT_TRUE(w.add(rpdo));
  ASSERT_TRUE(w.add(sync));
  const std::vector<std::uint8_t> expected = {
      0x54, 0x43, 0x41, 0x4E, 0x02, 0x02, 0x00, 0x00,                                                  //
      0x00, 0x06, 0x00, 0x00, 0x03, 0x02, 0x00, 0x00, 0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00, 0x00, 0x00,  //
      0x00, 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(bytes_of(w), expected);
}

TEST(UdpCanBatch, RoundTripsEveryKindOfFrameInOrder) {
  CanFrame ext = make_frame(0x1234'5678, 8, 1);
  ext.extended = true;
  CanFrame rtr = make_frame(0x701, 0, 0);
  rtr.rtr = true;
  rtr.dlc = 1;
  const std::vector<CanFrame> frames = {make_frame(0x181, 6, 10), make_frame(0x7FF, 0, 0), ext, rtr};
  BatchWriter w;
  for (const CanFrame& f : frames) ASSERT_TRUE(w.add(f));
  ASSERT_TRUE(w.add_error_report(can_error::kBusOff, {}));
  const DatagramReader r(w.bytes());
  ASSERT_EQ(r.status(), Decoded::frame);
  EXPECT_EQ(r.version(), udp_can::kBatchVersion);
  ASSERT_EQ(r.count(), frames.size() + 1);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    CanFrame got;
    ASSERT_EQ(r.read(i, got), Decoded::frame) << i;
    EXPECT_EQ(got, frames[i]) << i;
  }
  CanFrame report;
  EXPECT_EQ(r.read(frames.size(), report), Decoded::error_report);
  EXPECT_EQ(report.id, can_error::kBusOff);
}

TEST(UdpCanBatch, WriterHoldsAtMostSixtyFourFramesAndIsReusable) {
  BatchWriter w;
  for (std::size_t i = 0; i < udp_can::kMaxBatchFrames; ++i) ASSERT_TRUE(w.add(make_frame(0x100, 8, 0xFF)));
  EXPECT_TRUE(w.full());
  EXPECT_FALSE(w.add(make_frame(0x100, 1, 0)));
  EXPECT_EQ(w.bytes().size(), udp_can::kMaxDatagramBytes);
  w.clear();
  ASSERT_TRUE(w.add(make_frame(0x101, 1, 7)));
  // Bytes of the earlier, longer frame in that slot must not show through.
  const std::vector<std::uint8_t> b = bytes_of(w);
  ASSERT_EQ(b.size(), udp_can::kBatchHeaderBytes + udp_can::kBatchRecordBytes);
  EXPECT_EQ(b[16], 7);  // record 0's data starts at byte 8 + 8
  for (std::size_t i = 17; i < 24; ++i) EXPECT_EQ(b[i], 0) << i;
}

TEST(UdpCanBatch, ReaderDropsBadHeadersWhole) {
  BatchWriter w;
  w.add(make_frame(0x181, 6, 1));
  w.add(make_frame(0x182, 6, 2));
  const std::vector<std::uint8_t> good = bytes_of(w);
  const auto status_of = [](std::vector<std::uint8_t> b) { return DatagramReader(b).status(); };
  EXPECT_EQ(status_of(good), Decoded::frame);
  std::vector<std::uint8_t> b = good;
  b.pop_back();
  EXPECT_EQ(status_of(b), Decoded::bad_size) << "truncated";
  b = good;
  b.push_back(0);
  EXPECT_EQ(status_of(b), Decoded::bad_size) << "padded";
  b = good;
  b[5] = 3;
  EXPECT_EQ(status_of(b), Decoded::bad_size) << "count says more than there is";
  b = good;
  b[5] = 0;
  EXPECT_EQ(status_of(b), Decoded::bad_size) << "count 0";
  b.assign(udp_can::kBatchHeaderBytes + 65 * udp_can::kBatchRecordBytes, 0);
  std::copy(good.begin(), good.begin() + 8, b.begin());
  b[5] = 65;
  EXPECT_EQ(status_of(b), Decoded::bad_size) << "more than 64";
  b = good;
  b[7] = 1;
  EXPECT_EQ(status_of(b), Decoded::bad_reserved);
  b = good;
  b[1] = 'X';
  EXPECT_EQ(status_of(b), Decoded::bad_magic);
  b = good;
  b[4] = 3;
  EXPECT_EQ(status_of(b), Decoded::bad_version);
  EXPECT_EQ(status_of({'T', 'C', 'A'}), Decoded::bad_size);
}

TEST(UdpCanBatch, ReaderDropsABadRecordOnly) {
  BatchWriter w;
  w.add(make_frame(0x181, 6, 1));
  w.add(make_frame(0x182, 6, 2));
  w.add(make_frame(0x183, 6, 3));
  std::vector<std::uint8_t> b = bytes_of(w);
  b[8 + 16 + 1] = 9;  // the second record's dlc
  const DatagramReader r(b);
  ASSERT_EQ(r.status(), Decoded::frame);
  CanFrame got;
  EXPECT_EQ(r.read(0, got), Decoded::frame);
  EXPECT_EQ(r.read(1, got), Decoded::bad_dlc);
  EXPECT_EQ(r.read(2, got), Decoded::frame);
  EXPECT_EQ(got.id, 0x183U);
  b[8 + 16 + 1] = 6;
  b[8 + 16 + 2] = 1;  // its reserved bytes
  EXPECT_EQ(DatagramReader(b).read(1, got), Decoded::bad_reserved);
}

TEST(UdpCanBatch, ReaderTakesVersionOneAsOneFrame) {
  const udp_can::Datagram d = udp_can::encode(make_frame(0x181, 6, 3));
  const DatagramReader r(d);
  ASSERT_EQ(r.status(), Decoded::frame);
  EXPECT_EQ(r.version(), udp_can::kVersion);
  ASSERT_EQ(r.count(), 1U);
  CanFrame got;
  EXPECT_EQ(r.read(0, got), Decoded::frame);
  EXPECT_EQ(got, make_frame(0x181, 6, 3));
}

TEST(UdpCanBusBatch, FramesWaitForFlushAndGoOutAsOneDatagram) {
  RawPeer peer;
  auto bus = open_bus(peer.port(), true);
  ASSERT_EQ(bus->send(make_frame(0x203, 6, 1)), CanResult::ok);
  ASSERT_EQ(bus->send(make_frame(0x204, 6, 2)), CanResult::ok);
  CanFrame sync;
  sync.id = 0x080;
  ASSERT_EQ(bus->send(sync), CanResult::ok);
  EXPECT_TRUE(peer.nothing_queued()) << "nothing leaves before flush()";
  EXPECT_EQ(bus->counters().tx_frames, 0U);
  ASSERT_EQ(bus->flush(), CanResult::ok);
  const std::vector<std::uint8_t> d = peer.receive();
  const DatagramReader r(d);
  ASSERT_EQ(r.status(), Decoded::frame);
  ASSERT_EQ(r.count(), 3U);
  CanFrame got;
  r.read(2, got);
  EXPECT_EQ(got, sync);
  EXPECT_TRUE(peer.nothing_queued());
  EXPECT_EQ(bus->counters().tx_frames, 3U);
  EXPECT_EQ(bus->flush(), CanResult::ok) << "an empty flush sends nothing";
  EXPECT_TRUE(peer.nothing_queued());
}

TEST(UdpCanBusBatch, ALongBurstGoesOutInFullDatagramsInOrder) {
  RawPeer peer;
  auto bus = open_bus(peer.port(), true);
  for (std::uint32_t i = 0; i < 70; ++i) ASSERT_EQ(bus->send(make_frame(0x100 + i, 1, 0)), CanResult::ok);
  ASSERT_EQ(bus->flush(), CanResult::ok);
  std::uint32_t next = 0x100;
  for (std::size_t expected : {std::size_t{64}, std::size_t{6}}) {
    const std::vector<std::uint8_t> d = peer.receive();
    const DatagramReader r(d);
    ASSERT_EQ(r.count(), expected);
    for (std::size_t i = 0; i < r.count(); ++i) {
      CanFrame got;
      r.read(i, got);
      EXPECT_EQ(got.id, next++);
    }
  }
}

TEST(UdpCanBusBatch, WithoutBatchEveryFrameIsAVersionOneDatagramAtOnce) {
  RawPeer peer;
  auto bus = open_bus(peer.port(), false);
  ASSERT_EQ(bus->send(make_frame(0x203, 6, 1)), CanResult::ok);
  const std::vector<std::uint8_t> d = peer.receive();
  ASSERT_EQ(d.size(), udp_can::kDatagramBytes);
  EXPECT_EQ(d[4], udp_can::kVersion);
}

TEST(UdpCanBusBatch, ReceiveHandsOutABatchOneFrameAtATimeAndReadsBothVersions) {
  RawPeer peer;
  auto bus = open_bus(peer.port(), false);
  BatchWriter w;
  w.add(make_frame(0x181, 6, 1));
  w.add(make_frame(0x281, 5, 2));
  peer.send_to(bus->local_port(), bytes_of(w));
  const udp_can::Datagram v1 = udp_can::encode(make_frame(0x701, 1, 5));
  peer.send_to(bus->local_port(), {v1.begin(), v1.end()});
  for (std::uint32_t id : {0x181U, 0x281U, 0x701U}) {
    CanFrame got;
    ASSERT_EQ(bus->receive(got, kWaitNs), CanResult::ok);
    EXPECT_EQ(got.id, id);
  }
  CanFrame got;
  EXPECT_EQ(bus->receive(got, 0), CanResult::timeout);
  EXPECT_EQ(bus->counters().rx_frames, 3U);
}

TEST(UdpCanBusBatch, BadRecordsAreCountedAndErrorReportsAbsorbed) {
  RawPeer peer;
  auto bus = open_bus(peer.port(), false);
  BatchWriter w;
  w.add_error_report(can_error::kBusOff, {});
  w.add(make_frame(0x181, 6, 1));
  std::vector<std::uint8_t> b = bytes_of(w);
  b.insert(b.end(), b.end() - 16, b.end());  // a third record, made bad below
  b[5] = 3;
  b[8 + 32 + 1] = 9;
  peer.send_to(bus->local_port(), b);
  CanFrame got;
  ASSERT_EQ(bus->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got.id, 0x181U);
  EXPECT_EQ(bus->receive(got, 0), CanResult::timeout);
  EXPECT_TRUE(bus->counters().bus_off);
  EXPECT_EQ(bus->counters().rx_malformed, 1U);
  EXPECT_EQ(bus->dropped(Decoded::bad_dlc), 1U);
  EXPECT_EQ(bus->send(make_frame(0x201, 1, 0)), CanResult::bus_off) << "bus-off refuses before queueing";
}

TEST(UdpCanBusBatch, TwoBatchingBusesTalk) {
  std::string error;
  auto a = open_bus(9, true);  // remote set below
  auto b = open_bus(a->local_port(), true);
  ASSERT_TRUE(a->set_remote({"127.0.0.1", b->local_port()}, error)) << error;
  ASSERT_EQ(a->send(make_frame(0x201, 6, 1)), CanResult::ok);
  ASSERT_EQ(a->send(make_frame(0x080, 0, 0)), CanResult::ok);
  ASSERT_EQ(a->flush(), CanResult::ok);
  CanFrame got;
  ASSERT_EQ(b->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got.id, 0x201U);
  ASSERT_EQ(b->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got.id, 0x080U);
}

}  // namespace
}  // namespace tensegrity::fw

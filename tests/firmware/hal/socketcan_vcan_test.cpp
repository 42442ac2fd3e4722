// SPDX-License-Identifier: Apache-2.0
// SocketCAN against a real kernel. Self-contained (links statically where the
// toolchain allows) so it can run in a bare VM initramfs:
//   modprobe vcan; ip link add dev vcan0 type vcan; ip link set vcan0 up
//   TENSEGRITY_VCAN_IF=vcan0 ./test_socketcan_vcan
// Where the kernel has no AF_CAN or the interface is missing, the vcan cases skip
// with the reason.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>

#include "firmware/hal/socketcan_bus.hpp"

namespace tensegrity::fw {
namespace {

constexpr std::int64_t kWaitNs = 500'000'000;

std::string interface_name() {
  const char* env = std::getenv("TENSEGRITY_VCAN_IF");
  return env != nullptr && *env != '\0' ? env : "vcan0";
}

// Empty when AF_CAN works; otherwise why not.
std::string af_can_unavailable_reason() {
  const int fd = ::socket(AF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return std::string("socket(AF_CAN) failed: ") + std::strerror(errno);
  ::close(fd);
  return {};
}

CanFrame make_frame(std::uint32_t id, std::uint8_t dlc, std::uint8_t seed) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  for (std::uint8_t i = 0; i < dlc; ++i) f.data[i] = static_cast<std::uint8_t>(seed + i);
  return f;
}

TEST(SocketCanOpen, FailsWithAClearMessageWithoutKernelSupport) {
  const std::string reason = af_can_unavailable_reason();
  if (reason.empty()) GTEST_SKIP() << "this kernel has AF_CAN; nothing to check";
  std::string error;
  EXPECT_EQ(SocketCanBus::open(interface_name(), error), nullptr);
  EXPECT_THAT(error, ::testing::HasSubstr("socketcan: kernel has no CAN support (socket(AF_CAN) failed: "));
}

TEST(SocketCanOpen, MissingInterfaceIsNamed) {
  const std::string reason = af_can_unavailable_reason();
  if (!reason.empty()) GTEST_SKIP() << "kernel has no CAN support: " << reason;
  std::string error;
  EXPECT_EQ(SocketCanBus::open("tsgnoif0", error), nullptr);
  EXPECT_THAT(error, ::testing::HasSubstr("no interface 'tsgnoif0'"));
}

class SocketCanVcan : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string reason = af_can_unavailable_reason();
    if (!reason.empty()) GTEST_SKIP() << "kernel has no CAN support: " << reason;
    if (::if_nametoindex(interface_name().c_str()) == 0) {
      GTEST_SKIP() << "no interface " << interface_name()
                   << " (set TENSEGRITY_VCAN_IF or: ip link add dev vcan0 type vcan; ip link set vcan0 up)";
    }
    std::string error;
    a_ = SocketCanBus::open(interface_name(), error);
    ASSERT_TRUE(a_) << error;
    b_ = SocketCanBus::open(interface_name(), error);
    ASSERT_TRUE(b_) << error;
  }

  // Writes a raw kernel frame, as a CAN controller driver would deliver it.
  void inject(canid_t can_id, const std::array<std::uint8_t, 8>& data) {
    const int fd = ::socket(AF_CAN, SOCK_RAW, CAN_RAW);
    ASSERT_GE(fd, 0);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(::if_nametoindex(interface_name().c_str()));
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
    can_frame k{};
    k.can_id = can_id;
    k.can_dlc = 8;
    std::memcpy(k.data, data.data(), 8);
    ASSERT_EQ(::write(fd, &k, sizeof(k)), static_cast<ssize_t>(sizeof(k))) << std::strerror(errno);
    ::close(fd);
  }

  std::unique_ptr<SocketCanBus> a_;
  std::unique_ptr<SocketCanBus> b_;
};

TEST_F(SocketCanVcan, FramesTravelBothWays) {
  CanFrame ext = make_frame(0x1ABC'DEF0, 8, 7);
  ext.extended = true;
  CanFrame rtr = make_frame(0x701, 0, 0);
  rtr.rtr = true;
  rtr.dlc = 1;
  for (const CanFrame& f : {make_frame(0x181, 6, 1), ext, rtr}) {
    ASSERT_EQ(a_->send(f), CanResult::ok);
    CanFrame got;
    ASSERT_EQ(b_->receive(got, kWaitNs), CanResult::ok);
    EXPECT_EQ(got, f);
  }
  ASSERT_EQ(b_->send(make_frame(0x201, 6, 9)), CanResult::ok);
  CanFrame got;
  ASSERT_EQ(a_->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, make_frame(0x201, 6, 9));
  EXPECT_EQ(a_->counters().tx_frames, 3U);
  EXPECT_EQ(b_->counters().rx_frames, 3U);
}

TEST_F(SocketCanVcan, ReceiveTimesOut) {
  CanFrame got;
  EXPECT_EQ(b_->receive(got, 0), CanResult::timeout);
  EXPECT_EQ(b_->receive(got, 2'000'000), CanResult::timeout);
}

TEST_F(SocketCanVcan, FiltersSelectFrames) {
  const CanIdFilter only_0x181[] = {{0x181, 0x7FF, false}};
  ASSERT_EQ(b_->set_filters(only_0x181), CanResult::ok);
  CanFrame ext = make_frame(0x181, 1, 0);
  ext.extended = true;  // same number, other id kind: filtered out
  ASSERT_EQ(a_->send(make_frame(0x182, 1, 0)), CanResult::ok);
  ASSERT_EQ(a_->send(ext), CanResult::ok);
  ASSERT_EQ(a_->send(make_frame(0x181, 2, 5)), CanResult::ok);
  CanFrame got;
  ASSERT_EQ(b_->receive(got, kWaitNs), CanResult::ok);
  EXPECT_EQ(got, make_frame(0x181, 2, 5));
  EXPECT_EQ(b_->receive(got, 5'000'000), CanResult::timeout);

  ASSERT_EQ(b_->set_filters({}), CanResult::ok);
  ASSERT_EQ(a_->send(make_frame(0x181, 2, 5)), CanResult::ok);
  EXPECT_EQ(b_->receive(got, 5'000'000), CanResult::timeout) << "empty filter list receives nothing";
}

TEST_F(SocketCanVcan, BusOffErrorFrameIsCountedAndBlocksSending) {
  inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {});
  CanFrame got;
  EXPECT_EQ(b_->receive(got, 20'000'000), CanResult::timeout) << "error frames are not data";
  EXPECT_EQ(b_->counters().error_frames, 1U);
  EXPECT_TRUE(b_->counters().bus_off);
  EXPECT_EQ(b_->send(make_frame(0x201, 1, 0)), CanResult::bus_off);

  inject(CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_PASSIVE, 0, 0, 0, 0, 0, 0});
  inject(CAN_ERR_FLAG | CAN_ERR_RESTARTED, {});
  EXPECT_EQ(b_->receive(got, 20'000'000), CanResult::timeout);
  EXPECT_EQ(b_->counters().error_frames, 3U);
  EXPECT_FALSE(b_->counters().bus_off);
  EXPECT_EQ(b_->send(make_frame(0x201, 1, 0)), CanResult::ok);
}

}  // namespace
}  // namespace tensegrity::fw

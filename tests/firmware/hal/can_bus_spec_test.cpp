// SPDX-License-Identifier: Apache-2.0
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "firmware/hal/can_bus_spec.hpp"
#include "firmware/hal/make_can_bus.hpp"
#include "firmware/hal/udp_can_bus.hpp"

namespace tensegrity::fw {
namespace {

using ::testing::HasSubstr;

TEST(CanBusSpec, ParsesUdpWithAndWithoutBind) {
  CanBusSpec spec;
  std::string error;
  ASSERT_TRUE(parse_can_bus_spec("udp:127.0.0.1:7000", spec, error)) << error;
  EXPECT_EQ(spec.kind, CanBusSpec::Kind::udp);
  EXPECT_EQ(spec.remote.host, "127.0.0.1");
  EXPECT_EQ(spec.remote.port, 7000);
  EXPECT_EQ(spec.bind.host, "127.0.0.1") << "loopback unless told";
  EXPECT_EQ(spec.bind.port, 0);

  ASSERT_TRUE(parse_can_bus_spec("udp:hil.local:7000,bind=127.0.0.1:7001", spec, error)) << error;
  EXPECT_EQ(spec.remote.host, "hil.local");
  EXPECT_EQ(spec.bind.host, "127.0.0.1");
  EXPECT_EQ(spec.bind.port, 7001);
  EXPECT_FALSE(spec.batch);
}

TEST(CanBusSpec, ParsesBatchInAnyOrder) {
  CanBusSpec spec;
  std::string error;
  ASSERT_TRUE(parse_can_bus_spec("udp:127.0.0.1:7000,batch", spec, error)) << error;
  EXPECT_TRUE(spec.batch);
  EXPECT_EQ(spec.bind.port, 0);
  ASSERT_TRUE(parse_can_bus_spec("udp:127.0.0.1:7000,batch,bind=127.0.0.1:7001", spec, error)) << error;
  EXPECT_TRUE(spec.batch);
  EXPECT_EQ(spec.bind.port, 7001);
  ASSERT_TRUE(parse_can_bus_spec("udp:127.0.0.1:7000,bind=127.0.0.1:7001,batch", spec, error)) << error;
  EXPECT_TRUE(spec.batch);
  EXPECT_EQ(spec.bind.port, 7001);
}

TEST(CanBusSpec, ParsesSocketCan) {
  CanBusSpec spec;
  std::string error;
  ASSERT_TRUE(parse_can_bus_spec("socketcan:can0", spec, error)) << error;
  EXPECT_EQ(spec.kind, CanBusSpec::Kind::socketcan);
  EXPECT_EQ(spec.interface_name, "can0");
}

TEST(CanBusSpec, RejectsBadSpecsWithAReason) {
  struct Case {
    const char* spec;
    const char* reason;
  };
  for (const Case& c :
       {Case{"", "unknown CAN bus"}, Case{"tcp:1.2.3.4:5", "unknown CAN bus"}, Case{"udp:", "expected HOST:PORT"},
        Case{"udp:1.2.3.4", "expected HOST:PORT"}, Case{"udp::7000", "missing host"}, Case{"udp:h:70000", "0..65535"},
        Case{"udp:h:x1", "0..65535"}, Case{"udp:h:0", "must not be 0"}, Case{"udp:h:1,foo=1", "unknown option"},
        Case{"udp:h:1,bind=h", "bind"}, Case{"udp:h:1,batch,batch", "given twice"},
        Case{"udp:h:1,bind=h:2,bind=h:3", "given twice"}, Case{"udp:h:1,", "unknown option"},
        Case{"udp:h:1,batch=1", "unknown option"}, Case{"socketcan:", "interface name"},
        Case{"socketcan:a_very_long_interface_name", "interface name"}}) {
    CanBusSpec spec;
    std::string error;
    EXPECT_FALSE(parse_can_bus_spec(c.spec, spec, error)) << c.spec;
    EXPECT_THAT(error, HasSubstr(c.reason)) << c.spec;
  }
}

TEST(MakeCanBus, OpensUdp) {
  const MakeCanBusResult r = make_can_bus("udp:127.0.0.1:7000,bind=127.0.0.1:0");
  ASSERT_TRUE(r) << r.error;
  EXPECT_NE(dynamic_cast<UdpCanBus*>(r.bus.get()), nullptr);
}

TEST(MakeCanBus, ReportsBadSpecAndUnresolvableHost) {
  MakeCanBusResult r = make_can_bus("serial:/dev/ttyS0");
  EXPECT_FALSE(r);
  EXPECT_THAT(r.error, HasSubstr("serial:/dev/ttyS0"));
  r = make_can_bus("udp:no-such-host.invalid:7000");
  EXPECT_FALSE(r);
  EXPECT_THAT(r.error, HasSubstr("cannot resolve"));
}

TEST(MakeCanBus, SocketCanFailureNamesTheCause) {
  const MakeCanBusResult r = make_can_bus("socketcan:tsgabsent0");
  if (r) GTEST_SKIP() << "an interface named tsgabsent0 exists here";
  EXPECT_THAT(r.error, HasSubstr("socketcan: "));
  EXPECT_THAT(r.error, ::testing::AnyOf(HasSubstr("kernel has no CAN support"), HasSubstr("no interface")));
}

}  // namespace
}  // namespace tensegrity::fw

// SPDX-License-Identifier: Apache-2.0
// endcap_device_sim: two scripted drives and a load cell behind a UDP CAN bus, for
// running a realtime `endcap` by hand (timing measurements, demos). The end cap
// sends SYNC in realtime mode; the devices answer it.
//   endcap_device_sim BIND_PORT ENDCAP_PORT SECONDS [drive ids... default 1 3] (load cell 2)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "firmware/hal/udp_can_bus.hpp"
#include "hil/devices/cia402_drive.hpp"
#include "hil/devices/load_cell.hpp"

int main(int argc, char** argv) {
  using namespace tensegrity::fw;
  namespace sim = tensegrity::hil;
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s BIND_PORT ENDCAP_PORT SECONDS\n", argv[0]);
    return 2;
  }
  const auto port = [](const char* s) { return static_cast<std::uint16_t>(std::atoi(s)); };
  std::string error;
  auto bus = UdpCanBus::open({{"127.0.0.1", port(argv[2])}, {"127.0.0.1", port(argv[1])}}, error);
  if (!bus) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  sim::SimCia402Drive drive0(1), drive1(3);
  sim::SimLoadCell load_cell(2);
  load_cell.sample.tension_mn = {100'000, 100'000};
  sim::SimNode* devices[] = {&drive0, &drive1, &load_cell};
  sim::FrameOut out;
  const auto t0 = std::chrono::steady_clock::now();
  const auto now_ns = [&] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
  };
  const std::int64_t end_ns = static_cast<std::int64_t>(std::atof(argv[3]) * 1e9);
  for (sim::SimNode* d : devices) d->boot(now_ns(), out);
  std::int64_t next_tick_ns = 0;
  while (now_ns() < end_ns) {
    CanFrame f;
    if (bus->receive(f, 500'000) == CanResult::ok) {
      for (sim::SimNode* d : devices) d->on_frame(f, now_ns(), out);
      drive0.controlwords.clear();
      drive1.controlwords.clear();
    }
    if (now_ns() >= next_tick_ns) {
      for (sim::SimNode* d : devices) d->tick(now_ns(), out);
      next_tick_ns = now_ns() + 1'000'000;
    }
    for (const CanFrame& frame : out) bus->send(frame);
    out.clear();
  }
  return 0;
}

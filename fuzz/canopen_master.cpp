// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any sequence of CAN frames (SDO, PDO, EMCY, NMT heartbeat/boot-up,
// SYNC, unknown ids) into the end cap's CANopen master, during bring-up and after,
// with time moving forward. The master must neither crash nor leave its documented
// ranges (drive index, event queue), whatever arrives.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fuzzer/FuzzedDataProvider.h>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/hal/can_bus.hpp"

namespace fw = tensegrity::fw;
namespace canopen = tensegrity::fw::canopen;

namespace {

// Swallows what the master sends; nothing ever arrives through it (the fuzzer
// hands frames to on_frame directly).
class NullBus final : public fw::CanBus {
 public:
  fw::CanResult send(const fw::CanFrame&) override { return fw::CanResult::ok; }
  fw::CanResult receive(fw::CanFrame&, std::int64_t) override { return fw::CanResult::timeout; }
  fw::CanCounters counters() const override { return {}; }
};

canopen::CanopenMasterConfig config_from(FuzzedDataProvider& in) {
  canopen::CanopenMasterConfig config;
  config.drive_node_id = 1;
  config.load_cell_node_id = 3;
  config.drive_count = in.ConsumeBool() ? 2 : 1;
  config.extra_drive_node_ids[0] = 2;
  config.use_load_cell = in.ConsumeBool();
  config.sync_counter_max = in.ConsumeBool() ? 0 : 240;
  return config;
}

fw::CanFrame frame_from(FuzzedDataProvider& in) {
  fw::CanFrame frame;
  // Mostly ids the master listens to (0x000-0x7FF), now and then anything at all.
  frame.id =
      in.ConsumeBool() ? in.ConsumeIntegralInRange<std::uint32_t>(0, 0x7FF) : in.ConsumeIntegral<std::uint32_t>();
  frame.extended = in.ConsumeBool() && in.ConsumeBool();
  frame.rtr = in.ConsumeBool() && in.ConsumeBool();
  frame.dlc = in.ConsumeIntegralInRange<std::uint8_t>(0, 15);  // > 8 too: a broken driver
  for (auto& byte : frame.data) byte = in.ConsumeIntegral<std::uint8_t>();
  return frame;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  NullBus bus;
  canopen::CanopenMaster master(bus, config_from(in));
  std::int64_t now_ns = 0;
  if (in.ConsumeBool()) master.start_bring_up(now_ns);
  while (in.remaining_bytes() > 0) {
    now_ns += in.ConsumeIntegralInRange<std::int64_t>(0, 200'000'000);
    switch (in.ConsumeIntegralInRange<int>(0, 7)) {
      case 0: master.poll(now_ns); break;
      case 1:
        (void)master.write_target(in.ConsumeIntegralInRange<std::size_t>(0, 3), in.ConsumeFloatingPoint<double>());
        break;
      case 2: master.request_fault_reset(); break;
      default: master.on_frame(frame_from(in), now_ns); break;
    }
    canopen::MasterEvent event;
    while (master.pop_event(event)) {
    }
  }
  for (std::size_t i = 0; i < master.drive_count(); ++i) (void)master.drive(i).statusword;
  if (master.drive_count() < 1 || master.drive_count() > canopen::kMaxDriveNodes) std::abort();
  return 0;
}

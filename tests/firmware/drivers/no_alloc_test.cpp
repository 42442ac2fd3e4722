// SPDX-License-Identifier: Apache-2.0
// The control loop's calls into the master must not allocate: count every
// operator new in this binary and compare across a steady-state cycle.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/drivers/pdo_codec.hpp"

namespace {
std::atomic<std::size_t> g_allocations{0};
}

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace tensegrity::fw::canopen {
namespace {

class NullBus final : public CanBus {
 public:
  CanResult send(const CanFrame&) override { return CanResult::ok; }
  CanResult receive(CanFrame&, std::int64_t) override { return CanResult::timeout; }
  CanCounters counters() const override { return {}; }
};

TEST(CanopenMasterHotPath, CycleDoesNotAllocate) {
  NullBus bus;
  CanopenMasterConfig config;
  CanopenMaster master(bus, config);
  master.start_bring_up(0);
  const CanFrame frames[] = {
      encode_heartbeat(1, NmtState::operational),
      encode_drive_tpdo1(1, {0x0627, 1000}),
      encode_drive_tpdo2(1, {-20, 8}),
      encode_load_cell_tpdo1(2, {{1000, 2000}, 3, 1}),
      encode_emcy(1, {0x2310, 3, {}}),
      encode_drive_tpdo1(7, {0x0627, 1000}),
      encode_sync(),
  };
  const std::size_t before = g_allocations.load();
  for (int cycle = 0; cycle < 1000; ++cycle) {
    const std::int64_t now_ns = cycle * 1'000'000LL;
    for (const CanFrame& f : frames) master.on_frame(f, now_ns);
    master.poll(now_ns);
    master.write_target(0.9);
    master.send_sync();
    MasterEvent e;
    while (master.pop_event(e)) {
    }
  }
  EXPECT_EQ(g_allocations.load(), before);
}

}  // namespace
}  // namespace tensegrity::fw::canopen

// SPDX-License-Identifier: Apache-2.0
// comms_test_node: N end caps' DDS nodes (firmware/comms) in one process, each with
// a stub control loop (stub_loop.hpp), for the multi-process DDS tests. Runs until
// SIGTERM/SIGINT. Prints "READY" once every node is up.
//
//   comms_test_node --domain D [--endcaps 0-11] [--loop-hz 500] [--telemetry-hz 100]
//     [--host-loss continue|stop] [--stop-on-host-loss 6-11] [--host-timeout-s 1] [--host-boot-grace-s 30]
//     [--clock-offset-spread-s 0] [--storage DIR] [--motor-count 2] [--quiet]
//     [--stall-commands] [--dds-cut-signals] [--keystore DIR] [--unheard-rejoin-s S]
//     [--loop-stall-after-s S [--loop-stall-for-s D]] [--dds-mute-after-s S]
// --stall-commands: the stub loops never take a command from the mailbox (it
// fills up), but read the emergency-stop counter every cycle.
// --dds-cut-signals: SIGUSR1 cuts every node's DDS link, SIGUSR2 restores it.
// --keystore: DDS Security, end cap N with the keystore's enclave endcap_NN.
// --loop-stall-after-s: the nodes watch a loop-progress counter (as the endcap
// program's do) that moves until S seconds after the start, then hangs (for good, or
// for D seconds with --loop-stall-for-s).
// --dds-mute-after-s: S seconds after the start, each node's participant of that
// moment stops sending for good and still hears (EndcapNodeConfig::mute_requests).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/hal/storage.hpp"
#include "msgs/security.hpp"
#include "tests/firmware/comms/stub_loop.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
std::atomic<bool> g_link_cut{false};
std::atomic<std::uint32_t> g_mute_requests{0};
extern "C" void on_link_signal(int signal) { g_link_cut.store(signal == SIGUSR1); }
std::atomic<std::uint64_t> g_loop_progress{0};

// "0-11", "3", "0,2,5-7" -> bit mask
unsigned parse_set(const std::string& text) {
  unsigned mask = 0;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t comma = text.find(',', at);
    const std::string part = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    const std::size_t dash = part.find('-');
    const int lo = std::stoi(part.substr(0, dash));
    const int hi = dash == std::string::npos ? lo : std::stoi(part.substr(dash + 1));
    if (lo < 0 || hi > 15 || lo > hi) throw std::invalid_argument("bad end cap set '" + text + "'");
    for (int i = lo; i <= hi; ++i) mask |= 1U << i;
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return mask;
}

struct Endcap {
  std::unique_ptr<tensegrity::test::OffsetClock> clock;
  std::unique_ptr<tensegrity::fw::FileStorage> storage;
  std::unique_ptr<tensegrity::fw::app::PolicyStore> store;
  std::unique_ptr<tensegrity::fw::comms::EndcapNode> node;
  std::unique_ptr<tensegrity::test::StubLoop> loop;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace tensegrity;
  int domain = -1;
  unsigned endcaps = 0x0FFF;
  unsigned stop_set = 0;
  double loop_hz = 500.0;
  double spread_s = 0.0;
  std::string storage_dir;
  bool stall_commands = false;
  bool cut_signals = false;
  double loop_stall_after_s = -1.0;  // never
  double loop_stall_for_s = 1e9;     // for good
  double mute_after_s = -1.0;        // never
  std::string keystore;
  fw::comms::EndcapNodeConfig base;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--domain")
        domain = std::stoi(value());
      else if (arg == "--endcaps")
        endcaps = parse_set(value());
      else if (arg == "--loop-hz")
        loop_hz = std::stod(value());
      else if (arg == "--telemetry-hz")
        base.telemetry_rate_hz = std::stod(value());
      else if (arg == "--host-loss")
        base.host_loss = fw::comms::parse_host_loss_action(value());
      else if (arg == "--stop-on-host-loss")
        stop_set = parse_set(value());
      else if (arg == "--unheard-rejoin-s")
        base.unheard_rejoin_s = std::stod(value());
      else if (arg == "--host-timeout-s")
        base.host_timeout_s = std::stod(value());
      else if (arg == "--host-boot-grace-s")
        base.host_boot_grace_s = std::stod(value());
      else if (arg == "--clock-offset-spread-s")
        spread_s = std::stod(value());
      else if (arg == "--storage")
        storage_dir = value();
      else if (arg == "--motor-count")
        base.expect.motor_count = static_cast<std::uint32_t>(std::stoul(value()));
      else if (arg == "--quiet")
        base.log = false;
      else if (arg == "--stall-commands")
        stall_commands = true;
      else if (arg == "--dds-cut-signals")
        cut_signals = true;
      else if (arg == "--keystore")
        keystore = value();
      else if (arg == "--loop-stall-after-s")
        loop_stall_after_s = std::stod(value());
      else if (arg == "--loop-stall-for-s")
        loop_stall_for_s = std::stod(value());
      else if (arg == "--dds-mute-after-s")
        mute_after_s = std::stod(value());
      else
        throw std::invalid_argument("unknown argument " + arg);
    }
    if (domain < 0) throw std::invalid_argument("--domain is required");
    if (!(loop_hz > 0.0 && loop_hz <= 10000.0)) throw std::invalid_argument("--loop-hz must be in (0, 10000]");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "comms_test_node: %s\n", e.what());
    return 2;
  }
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  if (cut_signals) {
    std::signal(SIGUSR1, on_link_signal);
    std::signal(SIGUSR2, on_link_signal);
    base.link_cut = &g_link_cut;
  }

  std::jthread progress;
  if (loop_stall_after_s >= 0.0) {
    base.loop_progress = &g_loop_progress;
    progress = std::jthread([loop_stall_after_s, loop_stall_for_s](const std::stop_token& stop) {
      using seconds = std::chrono::duration<double>;
      const auto hang = std::chrono::steady_clock::now() + seconds(loop_stall_after_s);
      const auto resume = hang + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     seconds(std::min(loop_stall_for_s, 1e6)));
      while (!stop.stop_requested()) {
        const auto now = std::chrono::steady_clock::now();
        if (now < hang || now >= resume) g_loop_progress.fetch_add(1, std::memory_order_relaxed);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
  }

  std::jthread mute;
  if (mute_after_s >= 0.0) {
    base.mute_requests = &g_mute_requests;
    mute = std::jthread([mute_after_s](const std::stop_token& stop) {
      const auto at =
          std::chrono::steady_clock::now() +
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(mute_after_s));
      while (!stop.stop_requested() && std::chrono::steady_clock::now() < at) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      if (!stop.stop_requested()) g_mute_requests.fetch_add(1);
    });
  }

  std::mt19937_64 rng(1234);  // the same offsets every run
  std::uniform_real_distribution<double> offset(-spread_s, spread_s);
  std::vector<Endcap> caps;
  try {
    for (int e = 0; e < 16; ++e) {
      if ((endcaps & (1U << e)) == 0) continue;
      Endcap c;
      c.clock = std::make_unique<test::OffsetClock>(static_cast<std::int64_t>(offset(rng) * 1e9));
      if (!storage_dir.empty()) {
        const auto dir = std::filesystem::path(storage_dir) / ("endcap" + std::to_string(e));
        std::filesystem::create_directories(dir);
        c.storage = std::make_unique<fw::FileStorage>(dir);
        c.store = std::make_unique<fw::app::PolicyStore>(*c.storage, base.expect.motor_count, base.expect.limits);
        fw::app::StoredTable restored;
        std::string report;
        c.store->load(restored, report);
      }
      fw::comms::EndcapNodeConfig config = base;
      config.endcap_id = e;
      config.domain = domain;
      if (!keystore.empty()) {
        config.enclave_dir = msgs::enclave_dir(keystore, msgs::enclave_name(msgs::Role::endcap, e));
      }
      if ((stop_set & (1U << e)) != 0) config.host_loss = fw::comms::HostLossAction::stop;
      c.node = std::make_unique<fw::comms::EndcapNode>(config, *c.clock, c.store.get());
      c.loop =
          std::make_unique<test::StubLoop>(e, *c.node, *c.clock, loop_hz, config.expect.motor_count, stall_commands);
      c.node->start();
      c.loop->start();
      caps.push_back(std::move(c));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "comms_test_node: %s\n", e.what());
    return 1;
  }
  std::printf("READY\n");
  std::fflush(stdout);
  while (g_stop == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (auto& c : caps) c.loop->stop();
  for (auto& c : caps) c.node->stop();
  return 0;
}

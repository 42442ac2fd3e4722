// SPDX-License-Identifier: Apache-2.0
// `tensegrity record OUT.csv [--duration S]`: every telemetry sample to CSV, one
// row per sample, written from a queue so the DDS thread never waits on the disk.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <deque>
#include <mutex>
#include <thread>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"

namespace tensegrity::cli {
namespace {
std::atomic<bool> g_interrupted{false};
}

void add_record_command(CLI::App& app) {
  struct Args {
    std::string out;
    double duration_s = 0.0;
    GroundOptions ground;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("record", "Record the end caps' telemetry to CSV");
  cmd->add_option("out", args->out, "Output CSV file")->required();
  cmd->add_option("--duration", args->duration_s, "Seconds to record (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  add_ground_options(*cmd, args->ground, 5.0);
  cmd->callback([args] {
    std::FILE* f = std::fopen(args->out.c_str(), "w");
    if (f == nullptr) throw CommandError(ExitCode::failure, "cannot write " + args->out);
    std::fputs(
        "receive_host_ns,endcap,seq,host_time_ns,loop_time_ns,cycle,mode,fault,subinterval,motor_count,"
        "commanded_m_0,commanded_m_1,commanded_m_2,commanded_m_3,measured_m_0,measured_m_1,measured_m_2,"
        "measured_m_3,tension_n_0,tension_n_1,tension_n_2,tension_n_3,loop_overruns,policy_id,"
        "policy_version\n",
        f);
    std::mutex mutex;
    std::deque<std::pair<ground::msg::Telemetry_, std::int64_t>> queue;
    // Recording does not command anything: stay silent, do not pose as the host.
    auto station = make_station(args->ground, /*publish_heartbeat=*/false);
    station->on_telemetry([&](const ground::msg::Telemetry_& t, std::int64_t at) {
      std::lock_guard lock(mutex);
      queue.emplace_back(t, at);
    });
    std::signal(SIGINT, [](int) { g_interrupted = true; });
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(args->duration_s);
    std::uint64_t rows = 0;
    while (!g_interrupted && (args->duration_s <= 0.0 || std::chrono::steady_clock::now() < end)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::deque<std::pair<ground::msg::Telemetry_, std::int64_t>> batch;
      {
        std::lock_guard lock(mutex);
        batch.swap(queue);
      }
      for (const auto& [t, at] : batch) {
        const auto& c = t.commanded_rest_length_m();
        const auto& m = t.measured_rest_length_m();
        const auto& n = t.tension_n();
        std::fprintf(
            f,
            "%lld,%d,%u,%lld,%lld,%llu,%u,%u,%u,%u,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.3f,%.3f,%.3f,%.3f,"
            "%llu,%s,%u\n",
            static_cast<long long>(at), int{t.endcap_id()}, t.seq(), static_cast<long long>(t.host_time_ns()),
            static_cast<long long>(t.loop_time_ns()), static_cast<unsigned long long>(t.cycle()), unsigned{t.mode()},
            unsigned{t.fault()}, t.subinterval(), t.motor_count(), c[0], c[1], c[2], c[3], m[0], m[1], m[2], m[3], n[0],
            n[1], n[2], n[3], static_cast<unsigned long long>(t.loop_overruns()), t.active_policy_id().c_str(),
            t.active_policy_version());
        ++rows;
      }
    }
    station->on_telemetry(nullptr);
    std::fclose(f);
    std::printf("recorded %llu telemetry samples to %s\n", static_cast<unsigned long long>(rows), args->out.c_str());
  });
}

}  // namespace tensegrity::cli

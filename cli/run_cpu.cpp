// SPDX-License-Identifier: Apache-2.0
#include "cli/run_cpu.hpp"

#include <unistd.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace tensegrity::cli {

namespace {
std::int64_t clock_ns(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

double load_average_1min() {
  std::ifstream in("/proc/loadavg");
  double load = -1.0;
  in >> load;
  return load;
}

std::int64_t steal_ns() {
  // "cpu  user nice system idle iowait irq softirq steal ..." in USER_HZ ticks.
  std::ifstream in("/proc/stat");
  std::string label;
  long long fields[8] = {};
  if (!(in >> label) || label != "cpu") return -1;
  for (long long& f : fields) {
    if (!(in >> f)) return -1;
  }
  const long hz = ::sysconf(_SC_CLK_TCK);
  return hz > 0 ? fields[7] * (1'000'000'000LL / hz) : -1;
}

CpuSample sample_self() {
  CpuSample s;
  s.wall_ns = clock_ns(CLOCK_MONOTONIC);
  s.stepper_thread_ns = clock_ns(CLOCK_THREAD_CPUTIME_ID);
  s.emulator_process_ns = clock_ns(CLOCK_PROCESS_CPUTIME_ID);
  s.load_average_1min = load_average_1min();
  s.steal_ns = steal_ns();
  return s;
}

std::int64_t process_cpu_ns(pid_t pid) {
  if (pid <= 0) return -1;
  std::error_code ec;
  std::filesystem::directory_iterator tasks("/proc/" + std::to_string(pid) + "/task", ec);
  if (ec) return -1;
  std::int64_t sum = 0;
  for (const auto& task : tasks) {
    std::ifstream in(task.path() / "schedstat");
    long long run_ns = 0;
    // A thread that ended between the listing and the read has no file: skip it.
    if (in >> run_ns) sum += run_ns;
  }
  return sum;
}

}  // namespace tensegrity::cli

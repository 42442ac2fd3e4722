// SPDX-License-Identifier: Apache-2.0
// CPU time of the HIL's parts over one stretch of a run, for `bench hil`. Wall-clock
// speed on a machine shared with other work says little; CPU seconds per simulated
// second do not depend on what else runs (up to cache and frequency effects).
//
// Sources, all in nanoseconds: the stepper thread (CLOCK_THREAD_CPUTIME_ID, read on
// that thread), the whole emulator process (CLOCK_PROCESS_CPUTIME_ID) and every end
// cap's process: the sum over its threads of /proc/PID/task/TID/schedstat's first
// field (the scheduler's exact run time; /proc/PID/stat counts 10 ms ticks).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <vector>

namespace tensegrity::cli {

struct CpuSample {
  std::int64_t wall_ns = 0;
  std::int64_t stepper_thread_ns = 0;
  std::int64_t emulator_process_ns = 0;
  std::vector<std::int64_t> endcap_ns;  // per end cap; -1: no process
  double load_average_1min = -1.0;
  // Time the hypervisor ran something else while this machine's CPUs wanted to run
  // (/proc/stat's steal, all CPUs, 10 ms resolution): on a VM, a stall of the
  // stepper that no code of ours can cause. -1: not available.
  std::int64_t steal_ns = -1;
};

// On the stepper's thread: clocks of the caller's thread and process, the wall
// clock, the load average and the steal time. Cheap (/proc/loadavg and /proc/stat).
CpuSample sample_self();
// Run time of every thread of `pid` so far, or -1 when it is gone.
std::int64_t process_cpu_ns(pid_t pid);
double load_average_1min();
std::int64_t steal_ns();

}  // namespace tensegrity::cli

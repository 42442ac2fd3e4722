// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/mpi_launch.hpp"

#include <gnu/libc-version.h>
#include <sched.h>

#include <charconv>
#include <cstdlib>
#include <string_view>
#include <thread>

namespace tensegrity::sim::evolve {

bool mpi_built() {
#if TENSEGRITY_WITH_MPI
  return true;
#else
  return false;
#endif
}

std::optional<int> mpi_launch_size() {
  // Open MPI's mpirun, MPICH's hydra (and srun --mpi=pmi2), PMIx launchers.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    const char* value = std::getenv(name);
    if (value == nullptr) continue;
    const std::string_view text(value);
    int size = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), size);
    if (error == std::errc() && end == text.data() + text.size() && size > 0) return size;
  }
  // A PMIx launcher that does not export the size still names the rank.
  if (std::getenv("PMIX_RANK") != nullptr) return 0;
  return std::nullopt;
}

int usable_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

std::string build_fingerprint() {
#if defined(__x86_64__)
  // glibc picks FMA variants of exp, log, sin, ... on CPUs that have it, which may
  // round a last bit differently: part of what makes two machines' scores differ.
  const char* cpu = __builtin_cpu_supports("fma") ? "x86_64 with FMA" : "x86_64 without FMA";
#elif defined(__aarch64__)
  const char* cpu = "aarch64";
#elif defined(__arm__)
  const char* cpu = "arm";
#else
  const char* cpu = "other";
#endif
  return std::string("compiler ") + __VERSION__ + ", glibc " + gnu_get_libc_version() + ", " + cpu;
}

}  // namespace tensegrity::sim::evolve

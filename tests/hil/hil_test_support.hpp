// SPDX-License-Identifier: Apache-2.0
// What the HIL process tests share: the robot, two policies, default options and
// the checks that a run left nothing behind (no child process, no shared memory).
#pragma once

#include <dirent.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "hil/hil_run.hpp"
#include "hil/scenario.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"

// Twelve sanitized end caps (several times slower) and their DDS nodes cannot keep
// 1 kHz deadlines and the start's time sync on 2 cores: under AddressSanitizer a
// real-time run fails on timing, which says nothing about memory. Lockstep runs
// (the same code, no deadlines) stay in.
#ifdef __SANITIZE_ADDRESS__
#define TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN() GTEST_SKIP() << "real time is not meaningful under AddressSanitizer"
#else
#define TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN() static_cast<void>(0)
#endif

namespace tensegrity::hil::hil_test {

namespace fs = std::filesystem;

inline const sim::Robot& robot() {
  static const sim::Robot r = sim::load_robot(sim::robot_path_named("superball"));
  return r;
}

// A file that is removed when the test program ends.
struct TempFile {
  fs::path path;
  ~TempFile() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

// The hand-made development policy of tools/make_dev_policy.py.
inline const fs::path& policy_file() {
  static const TempFile file{[] {
    sim::Policy p;
    p.robot = robot().name;
    p.period_s = 4.0;
    p.complexity = 5;
    p.provenance.method = "hand";
    for (int m = 0; m < robot().cable_count(); ++m) {
      sim::CablePolicy c{m, robot().cables[m].owner, {}};
      for (int j = 0; j < 5; ++j)
        c.rest_lengths_m.push_back(0.85 + 0.15 * std::sin(2 * M_PI * j / 5 + 2 * M_PI * m / 24));
      p.cables.push_back(c);
    }
    const fs::path f = fs::temp_directory_path() / ("hil_test_policy_" + std::to_string(::getpid()) + ".json");
    sim::save_policy(f, p);
    return f;
  }()};
  return file.path;
}

// A policy from a short coevolution run on this robot (7.1 m in 60 s): it rolls,
// so a timing or phase error shows in the distance.
inline fs::path evolved_policy_file() {
  return fs::path(std::getenv("TENSEGRITY_SOURCE_DIR")) / "tests/hil/data/evolved-t4-n5.json";
}

inline HilOptions options(double duration_s, Provision provision = default_provision()) {
  HilOptions o;
  o.policy = policy_file();
  o.duration_s = duration_s;
  o.barrier_timeout_s = 2.0;
  o.boot_timeout_s = 20.0;
  o.provision = provision;
  return o;
}

// The scenario of a killed end cap whose program is started again.
inline std::vector<ScenarioEvent> kill_and_restart(int endcap, double kill_s, double restart_s) {
  ScenarioEvent kill;
  kill.time_s = kill_s;
  kill.endcap = endcap;
  kill.fault = FaultKind::kill_endcap;
  ScenarioEvent restart = kill;
  restart.time_s = restart_s;
  restart.fault = FaultKind::restart_endcap;
  return {kill, restart};
}

// Live children of this process (an orphaned end cap would be one, or would
// have been re-parented: the launcher's PR_SET_PDEATHSIG rules that out).
inline std::vector<int> child_pids() {
  std::vector<int> out;
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return out;
  while (dirent* d = ::readdir(proc)) {
    const std::string name = d->d_name;
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat("/proc/" + name + "/stat");
    std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
    const auto close = text.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    int ppid = 0;
    if (std::sscanf(text.c_str() + close + 2, "%c %d", &state, &ppid) == 2 && ppid == ::getpid()) {
      out.push_back(std::stoi(name));
    }
  }
  ::closedir(proc);
  return out;
}

// Fast DDS's shared-memory files (it leaves them behind when a process is killed).
inline std::set<std::string> dds_shm_files() {
  std::set<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/dev/shm", ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("fast", 0) == 0 || name.rfind("sem.fast", 0) == 0) out.insert(name);
  }
  return out;
}

}  // namespace tensegrity::hil::hil_test

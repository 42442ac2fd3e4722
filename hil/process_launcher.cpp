// SPDX-License-Identifier: Apache-2.0
#include "hil/process_launcher.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sched.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/exit_code.hpp"
#include "firmware/app/config.hpp"
#include "hil/endcap_config.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace fs = std::filesystem;

fs::path default_endcap_binary() {
  if (const char* env = std::getenv("TENSEGRITY_ENDCAP"); env != nullptr && *env != '\0') return env;
#ifdef TENSEGRITY_ENDCAP_BINARY
  return TENSEGRITY_ENDCAP_BINARY;
#else
  return "endcap";
#endif
}

ProcessLauncher::ProcessLauncher(const LauncherConfig& config, Provisioner& provisioner)
    : config_(config), provisioner_(provisioner), slots_(config.endcap_count) {
  if (!fs::exists(config_.endcap_binary)) {
    throw HilError("end-cap program not found: " + config_.endcap_binary.string() +
                   " (build the `endcap` target or set TENSEGRITY_ENDCAP)");
  }
  std::string templ = (fs::temp_directory_path() / "tensegrity-hil-XXXXXX").string();
  if (::mkdtemp(templ.data()) == nullptr) throw HilError(std::string("mkdtemp: ") + std::strerror(errno));
  dir_ = templ;
  std::vector<std::uint16_t> ports;
  try {
    ports = free_udp_ports(config_.endcap_count);
  } catch (const std::runtime_error& e) {
    throw HilError(e.what());
  }
  for (int e = 0; e < config_.endcap_count; ++e) {
    Slot& s = slots_[e];
    s.port = ports[e];
    const fs::path d = dir_ / ("endcap" + std::to_string(e));
    fs::create_directories(d / "store");
    s.config = d / "endcap.json";
    s.log = d / "endcap.log";
    s.stats = d / "stats.json";
    const int motors = e < static_cast<int>(config_.motors_per_endcap.size()) ? config_.motors_per_endcap[e] : 2;
    std::ofstream(s.config) << fw::app::config_to_json_text(endcap_config(config_, motors, s.port, d / "store"));
  }
}

ProcessLauncher::~ProcessLauncher() {
  try {
    shutdown();
  } catch (...) {
  }
  if (!config_.keep_dir && !dir_.empty()) {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
}

void ProcessLauncher::start_all() {
  for (int e = 0; e < endcap_count(); ++e) {
    bool skip = false;
    for (int n : config_.never_start) skip = skip || n == e;
    if (!skip) spawn(e, false);
  }
}

void ProcessLauncher::spawn(int e, bool restart) {
  Slot& s = slots_[e];
  // --hang-loop-signal: the hang_loop fault's test hook (SIGRTMIN), harmless unless sent.
  std::vector<std::string> args{config_.endcap_binary.string(),
                                "--id",
                                std::to_string(e),
                                "--config",
                                s.config.string(),
                                "--stats-json",
                                s.stats.string(),
                                "--hang-loop-signal"};
  for (auto& a : provisioner_.endcap_arguments(e, restart)) args.push_back(std::move(a));
  if (const auto extra = config_.extra_args.find(e); extra != config_.extra_args.end()) {
    args.insert(args.end(), extra->second.begin(), extra->second.end());
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int log_fd = ::open(s.log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw HilError(s.log.string() + ": " + std::strerror(errno));
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    throw HilError(std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(exit_status(ExitCode::cannot_exec));  // the launcher died before prctl
    ::setpgid(0, 0);
    // A restart is spawned by the stepper's thread, which runs SCHED_FIFO: the
    // program must not inherit that (its start-up, DDS participant included, would
    // outrank every end cap's loop and stall the stepper for most of a second).
    // The program raises its own loop thread's priority.
    const sched_param normal{};
    ::sched_setscheduler(0, SCHED_OTHER, &normal);
    ::dup2(log_fd, 1);
    ::dup2(log_fd, 2);
    // Nothing else of the launcher's: its DDS participant's sockets (Fast DDS does
    // not open them close-on-exec) stayed bound in every end cap, beyond the
    // launcher's own life.
    ::close_range(3, ~0U, 0);
    ::execv(argv[0], argv.data());
    ::_exit(exit_status(ExitCode::cannot_exec));
  }
  ::setpgid(pid, pid);  // also from here: no race with an early kill(-pid)
  ::close(log_fd);
  s.pid = pid;
  s.exit_status = -1;
  if (restart) ++s.restarts;
}

void ProcessLauncher::reap(int e, bool block) {
  Slot& s = slots_[e];
  if (s.pid <= 0) return;
  int status = 0;
  const pid_t r = ::waitpid(s.pid, &status, block ? 0 : WNOHANG);
  if (r != s.pid) return;
  s.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  s.pid = -1;
}

std::string ProcessLauncher::log_text(int e) const {
  std::ifstream in(slots_[e].log);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

double ProcessLauncher::cpu_s(int e) const {
  const Slot& s = slots_[e];
  if (s.pid <= 0) return s.cpu_before_s;
  std::ifstream in("/proc/" + std::to_string(s.pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  if (close == std::string::npos) return s.cpu_before_s;
  std::istringstream fields(text.substr(close + 2));
  std::string f;
  unsigned long long utime = 0, stime = 0;
  // Fields after the command: state(3) ... utime(14) stime(15).
  for (int i = 3; i <= 15 && (fields >> f); ++i) {
    if (i == 14) utime = std::stoull(f);
    if (i == 15) stime = std::stoull(f);
  }
  return s.cpu_before_s + static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

bool ProcessLauncher::listening(int e) {
  reap(e, false);
  if (slots_[e].pid <= 0) return false;
  char wanted[32];
  std::snprintf(wanted, sizeof wanted, "0100007F:%04X", slots_[e].port);
  std::ifstream in("/proc/net/udp");
  std::string line;
  while (std::getline(in, line)) {
    if (line.find(wanted) != std::string::npos) return true;
  }
  return false;
}

bool ProcessLauncher::exited(int e) {
  reap(e, false);
  return slots_[e].pid <= 0 && slots_[e].exit_status != -1;
}

std::string ProcessLauncher::describe(int e) {
  reap(e, false);
  const Slot& s = slots_[e];
  if (s.pid <= 0) {
    std::string last;
    std::istringstream log(log_text(e));
    for (std::string line; std::getline(log, line);) {
      if (!line.empty()) last = line;
    }
    if (s.exit_status == -1) return "not started";
    return "process exited with status " + std::to_string(s.exit_status) +
           (last.empty() ? "" : "; last log line: " + last);
  }
  std::ifstream in("/proc/" + std::to_string(s.pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  const char state = close != std::string::npos && close + 2 < text.size() ? text[close + 2] : '?';
  std::string what = state == 'T' ? "stopped (SIGSTOP?)" : state == 'Z' ? "exited" : "running";
  return "pid " + std::to_string(s.pid) + ", " + what;
}

void ProcessLauncher::kill(int e) {
  Slot& s = slots_[e];
  if (s.pid <= 0) return;
  s.cpu_before_s = cpu_s(e);
  ::kill(-s.pid, SIGKILL);
  reap(e, true);
}

void ProcessLauncher::restart(int e) {
  kill(e);
  // Its last snapshot, kept (a rename: this runs on the stepper's thread).
  Slot& s = slots_[e];
  const std::filesystem::path kept = s.stats.string() + "." + std::to_string(s.earlier_stats.size());
  std::error_code ec;
  std::filesystem::rename(s.stats, kept, ec);
  if (!ec) s.earlier_stats.push_back(kept);
  spawn(e, true);
  provisioner_.on_restart(e);
}

void ProcessLauncher::read_stats(const Slot& s, EndcapProcessReport& r) {
  for (const auto& path : s.earlier_stats) {
    try {
      r.earlier_link += fw::app::load_stats(path).link;
    } catch (const fw::app::StatsError&) {  // killed before its first snapshot
    }
  }
  if (!std::filesystem::exists(s.stats)) return;
  try {
    r.stats = fw::app::load_stats(s.stats);
  } catch (const fw::app::StatsError& e) {
    r.stats_error = e.what();
  }
}

namespace {
// Whether process `pid` has a handler for `signal` (SigCgt in /proc/PID/status):
// until the program installed it, the signal's default action would end it.
bool catches(pid_t pid, int signal) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("SigCgt:", 0) != 0) continue;
    try {
      const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
      return ((mask >> (signal - 1)) & 1ULL) != 0;
    } catch (const std::exception&) {
      return false;
    }
  }
  return false;
}
}  // namespace

std::string ProcessLauncher::set_dds_link(int e, bool up) {
  if (!provisioner_.dds_link()) return "this run has no DDS link (provisioner " + provisioner_.name() + ")";
  reap(e, false);
  const Slot& s = slots_[e];
  if (s.pid <= 0) return "not running";
  const int signal = up ? SIGUSR2 : SIGUSR1;
  if (!catches(s.pid, signal)) return "its program does not handle the link signals (yet)";
  if (::kill(s.pid, signal) != 0) return std::string("kill: ") + std::strerror(errno);
  return "";
}

// SIGRTMIN+1: the end cap program's --dds-cut-signals mute (firmware/endcap/main.cpp).
std::string ProcessLauncher::mute_dds(int e) {
  if (!provisioner_.dds_link()) return "this run has no DDS link (provisioner " + provisioner_.name() + ")";
  reap(e, false);
  const Slot& s = slots_[e];
  if (s.pid <= 0) return "not running";
  if (!catches(s.pid, SIGRTMIN + 1)) return "its program does not handle the mute signal (yet)";
  if (::kill(s.pid, SIGRTMIN + 1) != 0) return std::string("kill: ") + std::strerror(errno);
  return "";
}

std::string ProcessLauncher::freeze(int e, bool loop_only) {
  reap(e, false);
  const Slot& s = slots_[e];
  if (s.pid <= 0) return "not running";
  const int signal = loop_only ? SIGRTMIN : SIGSTOP;
  if (loop_only && !catches(s.pid, signal)) return "its program does not handle the hang signal (yet)";
  if (::kill(s.pid, signal) != 0) return std::string("kill: ") + std::strerror(errno);
  return "";
}

void ProcessLauncher::terminate_all() {
  if (!terminate_cpu_s_.empty()) return;
  terminate_cpu_s_.resize(slots_.size());
  for (int e = 0; e < endcap_count(); ++e) {
    terminate_cpu_s_[e] = cpu_s(e);  // /proc/PID is gone once it exits
    if (slots_[e].pid > 0) {
      ::kill(-slots_[e].pid, SIGCONT);  // a stopped one could not act on SIGTERM
      ::kill(-slots_[e].pid, SIGTERM);
    }
  }
}

bool ProcessLauncher::all_exited() {
  bool alive = false;
  for (int e = 0; e < endcap_count(); ++e) {
    reap(e, false);
    alive = alive || slots_[e].pid > 0;
  }
  return !alive;
}

std::vector<EndcapProcessReport> ProcessLauncher::shutdown() {
  if (shut_down_) return reports_;
  shut_down_ = true;
  terminate_all();
  const std::vector<double> cpu = terminate_cpu_s_;
  // Generous: on a host loaded by other real-time work a program's housekeeping
  // thread may wait seconds for a core, and a SIGKILL loses its stats.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    bool alive = false;
    for (int e = 0; e < endcap_count(); ++e) {
      reap(e, false);
      alive = alive || slots_[e].pid > 0;
    }
    if (!alive) break;
    if (std::chrono::steady_clock::now() > deadline) {
      for (int e = 0; e < endcap_count(); ++e) {
        if (slots_[e].pid > 0) ::kill(-slots_[e].pid, SIGKILL);
        reap(e, true);
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  for (int e = 0; e < endcap_count(); ++e) {
    EndcapProcessReport r;
    r.endcap = e;
    r.started = slots_[e].exit_status != -1;
    r.exit_status = slots_[e].exit_status;
    r.cpu_s = cpu[e];
    r.restarts = slots_[e].restarts;
    read_stats(slots_[e], r);
    reports_.push_back(r);
  }
  return reports_;
}

}  // namespace tensegrity::hil

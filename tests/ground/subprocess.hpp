// SPDX-License-Identifier: Apache-2.0
// A child process for the multi-process DDS tests: stdout and stderr go to files
// the test reads; the destructor stops it (SIGTERM, then SIGKILL) so no test
// leaves a node running.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace tensegrity::test {

class Subprocess {
 public:
  // `in_file`: the child's stdin (a FIFO the test writes keys into, say); empty: this
  // process's own.
  Subprocess(const std::vector<std::string>& argv, const std::filesystem::path& out_file,
             const std::filesystem::path& err_file, const std::filesystem::path& in_file = {})
      : out_file_(out_file) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (!in_file.empty()) posix_spawn_file_actions_addopen(&actions, 0, in_file.c_str(), O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
  }
  ~Subprocess() { stop(); }
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  pid_t pid() const { return pid_; }
  std::string output() const {
    std::ifstream in(out_file_);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  bool wait_for_output(const std::string& needle, std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (output().find(needle) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  // Waits for the child to exit by itself: its exit code, 128 + the signal that
  // ended it (as a shell reports it), or -1 when it is still running at `timeout`
  // (then it is killed).
  int wait_exit(std::chrono::milliseconds timeout) {
    if (pid_ <= 0) return -1;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill_hard();
    return -1;
  }
  void kill_hard() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  // SIGTERM, then SIGKILL after `grace`. Its exit code, 128 + the signal that ended
  // it, or -1 when it had to be killed (or was not running); then what its threads
  // were doing goes to stderr, for the test's log.
  int stop(std::chrono::milliseconds grace = std::chrono::seconds(3)) {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + grace;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::fprintf(stderr, "pid %d still there %lld ms after SIGTERM:\n%s", static_cast<int>(pid_),
                 static_cast<long long>(grace.count()), thread_states().c_str());
    kill_hard();
    return -1;
  }
  // One line per thread: id, name, state (R, S, D, Z...) and the kernel function it
  // waits in.
  std::string thread_states() const {
    std::string lines;
    std::error_code ec;
    const std::filesystem::path tasks = "/proc/" + std::to_string(pid_) + "/task";
    for (const auto& task : std::filesystem::directory_iterator(tasks, ec)) {
      const auto read = [&task](const char* name) {
        std::ifstream in(task.path() / name);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        while (!text.empty() && text.back() == '\n') text.pop_back();
        return text;
      };
      const std::string stat = read("stat");
      const auto close = stat.rfind(')');
      const std::string state = close != std::string::npos && close + 2 < stat.size() ? stat.substr(close + 2, 1) : "?";
      lines += "  " + task.path().filename().string() + " " + read("comm") + " " + state + " " + read("wchan") + "\n";
    }
    return lines.empty() ? "  (no threads left)\n" : lines;
  }

 private:
  pid_t pid_ = -1;
  std::filesystem::path out_file_;
};

}  // namespace tensegrity::test

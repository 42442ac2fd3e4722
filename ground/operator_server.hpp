// SPDX-License-Identifier: Apache-2.0
// The console's side of its local socket (ground/operator_protocol.hpp): relays
// estop, stop and clear-fault from ground tools on this machine to the end caps
// through the console's long-lived, already authenticated station.
//
// Who may use it: the socket sits in a folder only its user may enter (0700), and
// each peer's uid is checked (SO_PEERCRED) against this process's, so a command
// still comes from someone who holds the ground identity's key, not from anyone on
// the machine. One thread per connection (at most kMaxConnections); commands run
// one at a time, and an emergency stop preempts whatever is in flight, an older
// estop too (its acknowledgement wait, not its effect: the preempted command was
// already sent); the end caps an older estop had not heard from join the newer one.
// Stopping the console never drops an emergency stop: one in flight, or asked for
// while stopping, runs to its end (every end cap acked, or its timeout); only the
// other commands end early.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <thread>

#include "ground/command.hpp"
#include "ground/operator_protocol.hpp"

namespace tensegrity::ground {

class OperatorServer {
 public:
  static constexpr int kMaxConnections = 8;
  using StationSource = std::function<std::shared_ptr<Station>()>;

  // Listens on `socket_path`, making its folder (0700). A socket left by a console
  // that died is replaced; one a live console answers on is refused (OperatorLinkError).
  OperatorServer(StationSource station, std::filesystem::path socket_path);
  ~OperatorServer();  // stops serving and removes the socket
  OperatorServer(const OperatorServer&) = delete;
  OperatorServer& operator=(const OperatorServer&) = delete;

  // Runs one command on the current station: what a connection asks for, and what
  // the console's own keys do.
  CommandReport run(const OperatorRequest& request);

  // Stops accepting (the socket removed), ends a stop or clear-fault in flight at
  // its next check (a few ms) and refuses new ones; emergency stops still run.
  void shutdown();

  const std::filesystem::path& socket_path() const { return socket_path_; }
  std::uint64_t served() const { return served_.load(); }
  std::uint64_t refused() const { return refused_.load(); }
  std::uint64_t asked() const { return asked_.load(); }  // commands taken, any source, done or not

 private:
  void accept_loop(const std::stop_token& stop);
  void serve(int raw_fd);
  void reap_finished();

  StationSource station_;
  std::filesystem::path socket_path_;
  std::atomic<int> listen_fd_{-1};
  std::mutex command_mutex_;            // one command at a time
  std::atomic<int> estops_waiting_{0};  // > 0: a command in flight yields
  std::atomic<bool> stopping_{false};
  std::uint16_t estop_handover_mask_ = 0;  // under command_mutex_
  std::atomic<std::uint64_t> served_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> asked_{0};
  std::mutex connections_mutex_;
  struct Connection {
    std::jthread thread;
    std::atomic<bool> done{false};
  };
  std::list<Connection> connections_;
  std::jthread acceptor_;
};

}  // namespace tensegrity::ground

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The process's one MPI connection. Only the thread that made the session calls MPI
// (MPI_THREAD_FUNNELED): evaluation threads never do. MPI errors are returned, not
// fatal, so that they become messages. Nothing here waits in MPI's own blocking
// calls, which spin on a core the evaluation threads of the same machine need, and
// cannot give up: sends and receives are polled with short sleeps, against a
// deadline where one is given.
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/exit_code.hpp"
#include "sim/evolve/mpi_wire.hpp"

namespace tensegrity::sim::evolve {

// The run cannot go on: a rank fell silent, broke the protocol, or MPI failed. The
// other ranks may be in any state, so the only way out is MpiSession::abort.
class MpiFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class MpiSession {
 public:
  // MPI_Init_thread; throws MpiFailure when MPI cannot start or lacks FUNNELED.
  MpiSession();
  // Rank 0 first tells every other rank to stop (stop_others) if it has not yet, so
  // that they leave their loop; then MPI_Finalize, which waits for every rank.
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  const std::string& host() const { return host_; }

  // MPI_Abort: mpirun ends every process of the job. Print the reason first.
  [[noreturn]] void abort(ExitCode code);

  // Returns when `bytes` may be reused (the message is on its way). Throws
  // MpiFailure on an MPI error or after `timeout_s` (<= 0: no limit).
  void send(int to, wire::Tag tag, const wire::Bytes& bytes, double timeout_s);

  struct Message {
    int from = 0;
    wire::Tag tag = wire::Tag::stop;
    wire::Bytes bytes;
  };
  // The next message from any rank, if one has arrived.
  std::optional<Message> try_receive();

  // Rank 0: tells every other rank to stop serving, once.
  void stop_others(double timeout_s);

 private:
  int rank_ = 0;
  int size_ = 1;
  std::string host_;
  bool stopped_others_ = false;
};

// The sleep between two polls: short while messages flow, growing to 2 ms when
// idle. An episode takes seconds; 2 ms of latency per team costs nothing, a
// spinning loop would cost a core.
class PollWait {
 public:
  // The pause to take now: reset by activity, doubled otherwise.
  std::chrono::microseconds next(bool activity);

 private:
  std::chrono::microseconds current_{0};
};

}  // namespace tensegrity::sim::evolve

// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/mpi_session.hpp"

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace tensegrity::sim::evolve {
namespace {

using Clock = std::chrono::steady_clock;

std::string error_text(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  if (MPI_Error_string(code, text, &length) != MPI_SUCCESS) return "MPI error " + std::to_string(code);
  return std::string(text, static_cast<std::size_t>(length));
}

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw MpiFailure(std::string(what) + ": " + error_text(code));
}

bool known_tag(int tag) {
  return tag >= static_cast<int>(wire::Tag::setup) && tag <= static_cast<int>(wire::Tag::stop);
}

}  // namespace

std::chrono::microseconds PollWait::next(bool activity) {
  using std::chrono::microseconds;
  current_ = activity ? microseconds(0) : std::clamp(current_ * 2, microseconds(20), microseconds(2000));
  return current_;
}

MpiSession::MpiSession() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised != 0) throw MpiFailure("MPI is already initialised in this process");
  int provided = 0;
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  // From here on errors come back as codes (and become MpiFailure) instead of
  // killing the job from inside MPI with a message that names no rank's role.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw MpiFailure("this MPI library does not support threads (MPI_THREAD_FUNNELED)");
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  char name[MPI_MAX_PROCESSOR_NAME];
  int length = 0;
  if (MPI_Get_processor_name(name, &length) == MPI_SUCCESS) host_.assign(name, static_cast<std::size_t>(length));
}

MpiSession::~MpiSession() {
  if (rank_ == 0 && !stopped_others_) {
    try {
      stop_others(10.0);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "tensegrity: rank 0: %s; aborting the MPI job\n", e.what());
      abort(ExitCode::mpi);
    }
  }
  MPI_Finalize();
}

void MpiSession::abort(ExitCode code) {
  std::fflush(stdout);
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, exit_status(code));
  // MPI_Abort does not return; should an implementation do so anyway, leave.
  std::_Exit(exit_status(code));
}

void MpiSession::send(int to, wire::Tag tag, const wire::Bytes& bytes, double timeout_s) {
  if (bytes.size() > static_cast<std::size_t>(INT_MAX)) throw MpiFailure("message too large for MPI");
  MPI_Request request = MPI_REQUEST_NULL;
  check(MPI_Isend(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, static_cast<int>(tag), MPI_COMM_WORLD,
                  &request),
        "MPI_Isend");
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  PollWait wait;
  for (;;) {
    int done = 0;
    check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test");
    if (done != 0) return;
    if (timeout_s > 0.0 && Clock::now() > deadline) {
      // The request stays pending: the job is about to be aborted anyway.
      throw MpiFailure("rank " + std::to_string(to) + " took no " + wire::to_string(tag) + " message for " +
                       std::to_string(static_cast<long long>(timeout_s)) +
                       " s: it is stopped, hung or unreachable (--mpi-timeout sets this limit)");
    }
    std::this_thread::sleep_for(wait.next(false));
  }
}

std::optional<MpiSession::Message> MpiSession::try_receive() {
  int flag = 0;
  MPI_Status status;
  check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
  if (flag == 0) return std::nullopt;
  int count = 0;
  check(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
  Message message;
  message.from = status.MPI_SOURCE;
  message.bytes.resize(static_cast<std::size_t>(count));
  check(MPI_Recv(message.bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE),
        "MPI_Recv");
  if (!known_tag(status.MPI_TAG)) {
    throw MpiFailure("rank " + std::to_string(status.MPI_SOURCE) + " sent a message with unknown tag " +
                     std::to_string(status.MPI_TAG));
  }
  message.tag = static_cast<wire::Tag>(status.MPI_TAG);
  return message;
}

void MpiSession::stop_others(double timeout_s) {
  if (stopped_others_) return;
  stopped_others_ = true;
  for (int r = 1; r < size_; ++r) send(r, wire::Tag::stop, {}, timeout_s);
}

}  // namespace tensegrity::sim::evolve

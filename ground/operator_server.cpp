// SPDX-License-Identifier: Apache-2.0
#include "ground/operator_server.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <system_error>
#include <stdexcept>
#include <string>
#include <utility>

#include "ground/unix_socket.hpp"

namespace tensegrity::ground {
namespace {

constexpr std::size_t kMaxRequestBytes = 4096;
// A client sends its one line at once; one that does not is not kept.
constexpr std::chrono::milliseconds kRequestTimeout{2000};

// The socket's folder: made 0700 if missing; an existing one must already be
// private (a folder someone else controls could swap the socket or the folder).
void private_folder(const std::filesystem::path& folder) {
  struct stat st {};
  if (::lstat(folder.c_str(), &st) != 0 && errno == ENOENT) {
    std::filesystem::create_directories(folder);
    if (::chmod(folder.c_str(), 0700) != 0) throw OperatorLinkError(folder.string() + ": cannot chmod 700");
  }
  try {
    check_private_folder(folder);
  } catch (const std::runtime_error& e) {
    throw OperatorLinkError(std::string("the console's socket folder ") + e.what());
  }
}

}  // namespace

OperatorServer::OperatorServer(StationSource station, std::filesystem::path socket_path)
    : station_(std::move(station)), socket_path_(std::filesystem::absolute(socket_path).lexically_normal()) {
  if (!station_) throw std::invalid_argument("operator server: no station");
  private_folder(socket_path_.parent_path());
  try {
    listen_fd_ = listen_unix(socket_path_, 16).release();
  } catch (const std::runtime_error& e) {
    throw OperatorLinkError(e.what());
  }
  acceptor_ = std::jthread([this](const std::stop_token& stop) { accept_loop(stop); });
}

OperatorServer::~OperatorServer() {
  shutdown();
  std::lock_guard lock(connections_mutex_);
  connections_.clear();  // joins each: their commands end early (stopping_)
}

void OperatorServer::shutdown() {
  stopping_ = true;
  acceptor_.request_stop();
  if (acceptor_.joinable()) acceptor_.join();
  // Closed at once, so a tool finds no console and speaks itself instead of waiting.
  if (const int fd = listen_fd_.exchange(-1); fd >= 0) {
    ::unlink(socket_path_.c_str());
    ::close(fd);
  }
}

CommandReport OperatorServer::run(const OperatorRequest& request) {
  const bool estop = request.kind == CommandKind::emergency_stop;
  // What the operator's clear-fault has seen is what the console heard when it was
  // asked, not after a command ahead of it (an estop landing meanwhile is unseen).
  std::shared_ptr<EstopsSeen> seen;
  if (request.kind == CommandKind::clear_fault) {
    seen = std::make_shared<EstopsSeen>(estops_seen_now(*station_(), request.endcap_mask));
  }
  ++asked_;
  if (estop) ++estops_waiting_;
  std::unique_lock lock(command_mutex_);
  if (estop) --estops_waiting_;
  if (stopping_ && !estop) throw OperatorLinkError("the console is stopping");
  CommandOptions options;
  options.endcap_mask = request.endcap_mask;
  options.timeout_s = request.timeout_s;
  options.estops_seen = seen;
  // Any command in flight, an older estop included, yields to a newer estop; the
  // end caps an estop had not yet heard from pass to the one that took over. The
  // console stopping ends the others, never an estop.
  options.keep_going = [this, estop] { return estops_waiting_.load() == 0 && (estop || !stopping_.load()); };
  if (estop) {
    options.retry_interval_s = kEstopRetryIntervalS;
    options.endcap_mask = static_cast<std::uint16_t>(options.endcap_mask | std::exchange(estop_handover_mask_, 0));
  }
  CommandReport report;
  {
    const std::shared_ptr<Station> station = station_();
    report = send_command(*station, request.kind, 0, options);
  }
  if (estop && report.preempted) {
    for (const int e : report.missing())
      estop_handover_mask_ = static_cast<std::uint16_t>(estop_handover_mask_ | (1U << e));
  }
  return report;
}

void OperatorServer::accept_loop(const std::stop_token& stop) {
  const int listen_fd = listen_fd_.load();
  while (!stop.stop_requested()) {
    pollfd p{listen_fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    UniqueFd fd(::accept4(listen_fd, nullptr, nullptr, SOCK_CLOEXEC));
    if (!fd) {  // out of descriptors, say: do not spin
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    reap_finished();
    const long uid = peer_uid(fd.get());
    std::lock_guard lock(connections_mutex_);
    if (uid != static_cast<long>(::geteuid()) || connections_.size() >= kMaxConnections) {
      OperatorReply reply;
      reply.console_pid = ::getpid();
      reply.error = uid != static_cast<long>(::geteuid()) ? "the console serves its own user only"
                                                          : "the console is busy (8 connections open)";
      ++refused_;
      try {
        write_all(fd.get(), encode_reply(reply) + "\n");
      } catch (const std::runtime_error&) {  // the peer went away: nothing to tell
      }
      continue;
    }
    Connection& c = connections_.emplace_back();
    try {
      c.thread = std::jthread([this, &c, raw = fd.get()] {
        serve(raw);
        c.done = true;
      });
      (void)fd.release();                 // the thread owns it now
    } catch (const std::system_error&) {  // no thread: the descriptor closes with `fd`
      connections_.pop_back();
    }
  }
}

void OperatorServer::reap_finished() {
  std::lock_guard lock(connections_mutex_);
  connections_.remove_if([](const Connection& c) { return c.done.load(); });
}

void OperatorServer::serve(int raw_fd) {
  const UniqueFd fd(raw_fd);
  OperatorReply reply;
  reply.console_pid = ::getpid();
  try {
    const OperatorRequest request = decode_request(read_line(fd.get(), kMaxRequestBytes, kRequestTimeout));
    reply.report = run(request);
    ++served_;
    const CommandReport& r = reply.report;
    double last_s = 0.0;
    for (const auto& result : r.results) last_s = std::max(last_s, result.latency_s);
    std::fprintf(stderr, "console: relayed %s: %zu of %zu acked, last ack %.1f ms%s\n", to_string(r.kind),
                 r.results.size() - r.missing().size(), r.results.size(), last_s * 1e3,
                 r.preempted ? " (ended early)" : "");
  } catch (const PeerClosed&) {
    return;  // a connection without a request: another console checking that this one lives
  } catch (const std::exception& e) {
    reply.error = e.what();
    ++refused_;
  }
  try {
    write_all(fd.get(), encode_reply(reply) + "\n");
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "console: a client left before its reply: %s\n", e.what());
  }
}

}  // namespace tensegrity::ground

// SPDX-License-Identifier: Apache-2.0
// What a page elsewhere, or anyone on the machine, can make the view's server do:
// a huge body is refused without being kept, a Host that is not the view's is
// refused (DNS rebinding: a page on another name reading live telemetry), and the
// event streams, each holding a thread, cannot take every thread.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "view/server.hpp"

namespace tensegrity::view {
namespace {

using Clock = std::chrono::steady_clock;

ServerOptions options() {
  const auto three = std::filesystem::path(testing::TempDir()) / "three-limits";
  std::filesystem::create_directories(three / "build");
  std::ofstream(three / "build" / "three.module.js") << "export const REVISION = 'test';\n";
  ServerOptions o;
  o.port = 0;
  o.three_dir = three;
  return o;
}

// The peak resident size of this process (server and client both), in MB.
double peak_rss_mb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1.0;
}

constexpr std::size_t kHugeBytes = 400U << 20;

// Streams kHugeBytes in 64 KiB pieces, so the client never holds them.
bool send_huge(std::size_t offset, std::size_t length, httplib::DataSink& sink) {
  static const std::string piece(64 * 1024, 'x');
  const std::size_t n = std::min(length, piece.size());
  (void)offset;
  return sink.write(piece.data(), n);
}

TEST(ViewServerLimits, AHugeBodyIsRefusedWithoutBeingKept) {
  ViewServer server(options());
  server.json("/api/mode", [] { return std::string("{}"); });
  server.start();
  const double before = peak_rss_mb();
  httplib::Client client("127.0.0.1", server.port());
  client.set_write_timeout(60, 0);
  client.set_read_timeout(60, 0);
  const auto res = client.Post("/api/mode", kHugeBytes, send_huge, "application/octet-stream");
  ASSERT_TRUE(res) << httplib::to_string(res.error());
  EXPECT_EQ(res->status, 413);
  EXPECT_LT(peak_rss_mb() - before, 64.0) << "the server kept the body";
  EXPECT_EQ(client.Get("/api/mode")->status, 200) << "and it still answers";
}

TEST(ViewServerLimits, ABodyOfUnknownLengthIsNotReadWhole) {
  ViewServer server(options());
  server.json("/api/mode", [] { return std::string("{}"); });
  server.start();
  const double before = peak_rss_mb();
  httplib::Client client("127.0.0.1", server.port());
  std::size_t sent = 0;
  // Chunked: cpp-httplib 0.11 applies no payload limit to it.
  const auto res = client.Post(
      "/api/mode",
      [&sent](std::size_t, httplib::DataSink& sink) {
        if (sent >= kHugeBytes) {
          sink.done();
          return true;
        }
        static const std::string piece(64 * 1024, 'x');
        sent += piece.size();
        return sink.write(piece.data(), piece.size());
      },
      "application/octet-stream");
  // No answer at all: refused and closed before the client read it.
  if (res) {
    EXPECT_EQ(res->status, 411);
  }
  EXPECT_LT(peak_rss_mb() - before, 64.0) << "the server kept the body";
  EXPECT_EQ(httplib::Client("127.0.0.1", server.port()).Get("/api/mode")->status, 200);
}

// A page's event stream opened on a socket of its own (Host: 127.0.0.1:PORT unless
// given); status() is the answer's, once its first event came when it is 200.
class Stream {
 public:
  Stream(int port, const std::string& path, std::string host = "") : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    if (host.empty()) host = "127.0.0.1:" + std::to_string(port);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{3, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0) return;
    const std::string request = "GET " + path + " HTTP/1.1\r\nHost: " + host + "\r\n\r\n";
    if (::send(fd_, request.data(), request.size(), 0) != static_cast<ssize_t>(request.size())) return;
    char buffer[4096];
    while (got_.find("\r\n\r\n") == std::string::npos ||
           (status() == 200 && got_.find("retry:") == std::string::npos)) {
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      got_.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ~Stream() { ::close(fd_); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  int status() const { return got_.rfind("HTTP/1.1 ", 0) == 0 ? std::stoi(got_.substr(9, 3)) : -1; }

 private:
  int fd_;
  std::string got_;
};

TEST(ViewServerLimits, OnlyItsOwnHostNamesAreServed) {
  ServerOptions o = options();
  o.allowed_hosts = {"Ground.local"};
  ViewServer server(o);
  EventHub hub;
  server.json("/api/mode", [] { return std::string("{\"mode\":\"live\"}"); });
  server.events("/api/live/events", hub, [] { return std::string("event: hello\ndata: {}\n\n"); });
  server.start();
  httplib::Client client("127.0.0.1", server.port());
  const std::string port = ":" + std::to_string(server.port());
  for (const std::string& host :
       std::vector<std::string>{"127.0.0.1" + port, "localhost" + port, "LOCALHOST" + port, "[::1]" + port,
                                "ground.local" + port, "127.0.0.1", "192.0.2.7:9000"}) {
    EXPECT_EQ(client.Get("/api/mode", {{"Host", host}})->status, 200) << host;
  }
  for (const std::string& host :
       std::vector<std::string>{"evil.example" + port, "127.0.0.1.evil.example" + port, "localhost.evil.example",
                                "ground.local.evil.example" + port, "localhost:x", ":" + port}) {
    const auto res = client.Get("/api/mode", {{"Host", host}});
    EXPECT_EQ(res->status, 403) << host;
    EXPECT_EQ(res->body.find("live"), std::string::npos) << host;
    EXPECT_EQ(Stream(server.port(), "/api/live/events", host).status(), 403) << host;
  }
  EXPECT_EQ(hub.readers(), 0);
  EXPECT_TRUE(host_allowed("robot:8080", ServerOptions{"robot", 8080, {}, {}})) << "the name it is bound to";
}

TEST(ViewServerLimits, LiveStreamsAreBoundedAndThePageStaysAnswerable) {
  ViewServer server(options());
  EventHub hub;
  server.json("/api/mode", [] { return std::string("{\"mode\":\"live\"}"); });
  server.events("/api/live/events", hub, [] { return std::string("event: hello\ndata: {}\n\n"); });
  server.start();
  std::vector<std::unique_ptr<Stream>> open;
  for (std::size_t i = 0; i < kMaxEventStreams; ++i) {
    open.push_back(std::make_unique<Stream>(server.port(), "/api/live/events"));
    ASSERT_EQ(open.back()->status(), 200) << "stream " << i;
  }
  EXPECT_EQ(Stream(server.port(), "/api/live/events").status(), 503);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(2, 0);
  const auto t0 = Clock::now();
  for (int i = 0; i < 20; ++i) ASSERT_EQ(client.Get("/api/mode")->status, 200);
  EXPECT_EQ(client.Get("/")->status, 200);
  EXPECT_LT(Clock::now() - t0, std::chrono::seconds(2));
  // A page closed frees its place: its stream notices within its idle second.
  open.pop_back();
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  int status = 503;
  while (status == 503 && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    status = Stream(server.port(), "/api/live/events").status();
  }
  EXPECT_EQ(status, 200);
}

}  // namespace
}  // namespace tensegrity::view

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The view's HTTP server (cpp-httplib): the page from the embedded assets, three.js
// from Debian's libjs-three directory, and the mode's read-only JSON and event
// endpoints. Only GET (and HEAD) are served: every other method gets 405, so nothing
// a page sends can reach the robot through the view. What a page elsewhere could
// still do is held off too: a Host that is not this server's is refused (DNS
// rebinding), a request body is never taken whole, and the event streams, each
// holding a thread, are bounded so that the page and the API stay answerable.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "view/event_hub.hpp"

namespace httplib {
class Server;
}

namespace tensegrity::view {

struct ServerOptions {
  std::string bind = "127.0.0.1";
  int port = 8080;  // 0: any free port
  std::filesystem::path three_dir = "/usr/share/javascript/three";
  // Host names served besides localhost, IP literals and `bind` (a name the page
  // is opened under on the network, e.g. "ground.local").
  std::vector<std::string> allowed_hosts;
};

// HTTP threads, event streams open at once (each holds a thread; more get 503),
// and the largest request body read (more gets 413; the view takes no bodies).
inline constexpr std::size_t kHttpThreads = 24;
inline constexpr std::size_t kMaxEventStreams = 16;
inline constexpr std::size_t kMaxRequestBodyBytes = 64 * 1024;

// Whether a Host header names this server: localhost, an IP literal (a rebinding
// page's Host is its own DNS name), `bind`, or one of `allowed`; any port.
bool host_allowed(const std::string& host, const ServerOptions& options);

class ViewServer {
 public:
  // Checks that three.js is where the options say (InputError naming the package).
  explicit ViewServer(const ServerOptions& options);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  // GET `path` answers the JSON `body()` returns; nullopt answers 503 {"pending":true}
  // (data still being made, e.g. an evolution's best team being simulated).
  void json(const std::string& path, std::function<std::optional<std::string>()> body);
  // GET `path` is a server-sent event stream of `hub`, opened with the event
  // `hello()` returns (the state so far, so a page that connects late is complete).
  void events(const std::string& path, EventHub& hub, std::function<std::string()> hello);

  // Binds and serves from a thread; throws InputError when it cannot bind.
  void start();
  void stop();
  int port() const { return port_; }
  std::string url() const;

 private:
  ServerOptions options_;
  std::unique_ptr<httplib::Server> http_;
  std::thread thread_;
  std::vector<EventHub*> hubs_;          // closed on stop, so that open streams end
  std::atomic<std::size_t> streams_{0};  // event streams open now
  int port_ = 0;
};

}  // namespace tensegrity::view

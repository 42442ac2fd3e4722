// SPDX-License-Identifier: Apache-2.0
#include "view/server.hpp"

#include <arpa/inet.h>
#include <httplib.h>

#include <cctype>

#include "view/assets.hpp"
#include "view/csv_table.hpp"

namespace tensegrity::view {

namespace {

constexpr const char* kThreeModule = "build/three.module.js";
// With a parameter these types are not ones cpp-httplib compresses: on loopback
// compression only costs time (its Brotli runs at the slowest quality), and
// three.js is a megabyte.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

void serve_asset(const httplib::Request& req, httplib::Response& res) {
  const Asset* a = find_asset(req.path == "/" ? "/index.html" : req.path);
  if (a == nullptr) {
    res.status = 404;
    res.set_content("not found\n", "text/plain");
    return;
  }
  res.set_header("Cache-Control", "no-cache");
  res.set_content(std::string(a->body), std::string(a->content_type));
}

void refuse(const httplib::Request&, httplib::Response& res) {
  res.status = 405;
  res.set_header("Allow", "GET, HEAD");
  res.set_content("the view is read-only\n", "text/plain");
}

bool ip_literal(const std::string& name) {
  in6_addr a6{};
  in_addr a4{};
  if (name.size() > 2 && name.front() == '[' && name.back() == ']') {
    return ::inet_pton(AF_INET6, name.substr(1, name.size() - 2).c_str(), &a6) == 1;
  }
  return ::inet_pton(AF_INET, name.c_str(), &a4) == 1;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Before routing, so a refused request's body is never read: a Host that is not
// this server's, and a body of unknown length (chunked), which cpp-httplib 0.11
// would read whole whatever the payload limit.
httplib::Server::HandlerResponse screen(const httplib::Request& req, httplib::Response& res,
                                        const ServerOptions& options) {
  if (!req.has_header("Host")) {
    res.status = 400;
    res.set_content("no Host header\n", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  }
  const std::string host = req.get_header_value("Host");
  if (!host_allowed(host, options)) {
    res.status = 403;
    res.set_content("Host '" + host +
                        "' is not this view's (DNS rebinding protection): open it as http://127.0.0.1:PORT/ or "
                        "name the host with --allow-host\n",
                    "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.has_header("Transfer-Encoding")) {
    res.status = 411;
    res.set_content("the view takes no request body of unknown length\n", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

}  // namespace

bool host_allowed(const std::string& host, const ServerOptions& options) {
  // The name without its port: "[::1]:8080" -> "[::1]", "a.b:8080" -> "a.b".
  std::string name = lower(host);
  const std::size_t colon = name.rfind(':');
  if (colon != std::string::npos && name.find(']', colon) == std::string::npos) {
    const std::string port = name.substr(colon + 1);
    if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos) return false;
    name.resize(colon);
  }
  if (name.empty()) return false;
  if (name == "localhost" || ip_literal(name) || name == lower(options.bind)) return true;
  for (const std::string& allowed : options.allowed_hosts) {
    if (name == lower(allowed)) return true;
  }
  return false;
}

ViewServer::ViewServer(const ServerOptions& options) : options_(options), http_(std::make_unique<httplib::Server>()) {
  if (!std::filesystem::exists(options_.three_dir / kThreeModule)) {
    throw InputError((options_.three_dir / kThreeModule).string() +
                     " not found: install Debian's libjs-three (scripts/setup.sh does), or give --three-dir");
  }
  http_->new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  http_->set_pre_routing_handler(
      [this](const httplib::Request& req, httplib::Response& res) { return screen(req, res, options_); });
  // A body above the limit is skipped, not kept, and answered 413.
  http_->set_payload_max_length(kMaxRequestBodyBytes);
  // One request per connection: cpp-httplib serves a connection on one thread,
  // so an idle keep-alive connection would hold one for 5 s, and the body of a
  // request refused before it was read would be parsed as the next request.
  http_->set_keep_alive_max_count(1);
  http_->set_file_extension_and_mimetype_mapping("js", kJavaScript);
  http_->set_mount_point("/three", options_.three_dir.string());
  http_->Get(R"(/|/index\.html|/js/[A-Za-z0-9_\-]+\.js|/[A-Za-z0-9_\-]+\.css)", serve_asset);
  for (const char* any : {".*"}) {
    http_->Post(any, refuse);
    http_->Put(any, refuse);
    http_->Delete(any, refuse);
    http_->Patch(any, refuse);
    http_->Options(any, refuse);
  }
}

ViewServer::~ViewServer() { stop(); }

void ViewServer::json(const std::string& path, std::function<std::optional<std::string>()> body) {
  http_->Get(path, [body = std::move(body)](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    const std::optional<std::string> text = body();
    if (!text) {
      res.status = 503;
      res.set_content("{\"pending\":true}", kJson);
      return;
    }
    res.set_content(*text, kJson);
  });
}

void ViewServer::events(const std::string& path, EventHub& hub, std::function<std::string()> hello) {
  hubs_.push_back(&hub);
  http_->Get(path, [this, &hub, hello = std::move(hello)](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    if (streams_.fetch_add(1) >= kMaxEventStreams) {
      streams_.fetch_sub(1);
      res.status = 503;
      res.set_header("Retry-After", "5");
      res.set_content("too many live pages open (" + std::to_string(kMaxEventStreams) + "): close one\n", "text/plain");
      return;
    }
    struct Stream {
      std::uint64_t cursor = 0;
      std::uint64_t skipped = 0;
      bool greeted = false;
    };
    auto stream = std::make_shared<Stream>();
    stream->cursor = hub.head();
    res.set_chunked_content_provider(
        "text/event-stream",
        [&hub, hello, stream](std::size_t, httplib::DataSink& sink) {
          if (!stream->greeted) {
            stream->greeted = true;
            hub.reader_joined();
            // retry: how soon the browser reconnects after the server went away.
            const std::string first = "retry: 1000\n\n" + hello();
            return sink.write(first.data(), first.size());
          }
          // A comment line when idle: a closed page is noticed within a second.
          std::string chunk = hub.take(&stream->cursor, 1000, &stream->skipped);
          if (hub.closed()) return false;
          if (chunk.empty()) chunk = ": idle\n\n";
          return sink.write(chunk.data(), chunk.size());
        },
        // Called once whatever happened, also when the provider never ran.
        [this, &hub, stream](bool) {
          if (stream->greeted) hub.reader_left();
          streams_.fetch_sub(1);
        });
  });
}

void ViewServer::start() {
  port_ = options_.port == 0 ? http_->bind_to_any_port(options_.bind) : options_.port;
  if (options_.port != 0 && !http_->bind_to_port(options_.bind, options_.port)) port_ = -1;
  if (port_ < 0) {
    throw InputError("cannot listen on " + options_.bind + ":" + std::to_string(options_.port) +
                     " (in use, or not an address of this machine): choose another with --port/--bind");
  }
  thread_ = std::thread([this] { http_->listen_after_bind(); });
}

void ViewServer::stop() {
  if (!thread_.joinable()) return;
  for (EventHub* hub : hubs_) hub->close();
  http_->stop();
  thread_.join();
}

std::string ViewServer::url() const {
  const std::string host = options_.bind.find(':') != std::string::npos ? "[" + options_.bind + "]" : options_.bind;
  return "http://" + host + ":" + std::to_string(port_) + "/";
}

}  // namespace tensegrity::view

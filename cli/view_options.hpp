// SPDX-License-Identifier: Apache-2.0
#pragma once
// The view server's flags, shared by `tensegrity view` and `tensegrity hil --view`.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "view/server.hpp"

namespace tensegrity::cli {

struct ViewServerArgs {
  int port = 8080;
  std::string bind = "127.0.0.1";
  std::string three_dir = "/usr/share/javascript/three";
  std::vector<std::string> allow_hosts;
};

inline void add_view_server_options(CLI::App& cmd, ViewServerArgs& args) {
  cmd.add_option("--port", args.port, "HTTP port of the page (0: any free one)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd.add_option("--bind", args.bind, "Address to listen on (0.0.0.0 shares the page with the network)")
      ->capture_default_str();
  cmd.add_option("--three-dir", args.three_dir, "Where three.js is (Debian's libjs-three)")->capture_default_str();
  cmd.add_option("--allow-host", args.allow_hosts,
                 "A host name the page is opened under besides localhost, an IP address and --bind (others are "
                 "refused: DNS rebinding); repeatable");
}

inline view::ServerOptions to_server_options(const ViewServerArgs& args) {
  view::ServerOptions o;
  o.port = args.port;
  o.bind = args.bind;
  o.three_dir = args.three_dir;
  o.allowed_hosts = args.allow_hosts;
  return o;
}

}  // namespace tensegrity::cli

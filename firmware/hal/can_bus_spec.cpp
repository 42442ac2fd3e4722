// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/can_bus_spec.hpp"

#include <charconv>

namespace tensegrity::fw {
namespace {

constexpr std::string_view kUdpPrefix = "udp:";
constexpr std::string_view kSocketCanPrefix = "socketcan:";
constexpr std::string_view kBindKey = "bind=";
constexpr std::string_view kBatchKey = "batch";
constexpr std::size_t kIfNameMax = 15;  // IFNAMSIZ - 1 on Linux

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

}  // namespace

bool parse_udp_endpoint(std::string_view text, UdpEndpoint& out, std::string& error) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string_view::npos) {
    error = "expected HOST:PORT, got " + quoted(text);
    return false;
  }
  const std::string_view host = text.substr(0, colon);
  const std::string_view port_text = text.substr(colon + 1);
  if (host.empty()) {
    error = "missing host in " + quoted(text);
    return false;
  }
  unsigned port = 0;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || ec != std::errc() || end != port_text.data() + port_text.size() || port > 65535) {
    error = "port must be a number 0..65535, got " + quoted(port_text);
    return false;
  }
  out.host = std::string(host);
  out.port = static_cast<std::uint16_t>(port);
  return true;
}

bool parse_can_bus_spec(std::string_view spec, CanBusSpec& out, std::string& error) {
  CanBusSpec result;
  if (spec.starts_with(kSocketCanPrefix)) {
    const std::string_view name = spec.substr(kSocketCanPrefix.size());
    if (name.empty() || name.size() > kIfNameMax || name.find_first_of("/:, \t") != std::string_view::npos) {
      error = "socketcan: interface name must be 1.." + std::to_string(kIfNameMax) +
              " characters without '/', ':', ',' or spaces, got " + quoted(name);
      return false;
    }
    result.kind = CanBusSpec::Kind::socketcan;
    result.interface_name = std::string(name);
    out = std::move(result);
    return true;
  }
  if (spec.starts_with(kUdpPrefix)) {
    const std::string_view rest = spec.substr(kUdpPrefix.size());
    const std::size_t comma = rest.find(',');
    const std::string_view remote = rest.substr(0, comma);
    if (!parse_udp_endpoint(remote, result.remote, error)) {
      error = "udp: remote: " + error;
      return false;
    }
    if (result.remote.port == 0) {
      error = "udp: remote port must not be 0";
      return false;
    }
    // Options after the remote, comma-separated, each at most once.
    bool seen_bind = false;
    for (std::size_t at = comma; at != std::string_view::npos;) {
      const std::size_t next = rest.find(',', at + 1);
      const std::string_view option =
          rest.substr(at + 1, next == std::string_view::npos ? std::string_view::npos : next - at - 1);
      const bool bind = option.starts_with(kBindKey);
      if ((bind && seen_bind) || (option == kBatchKey && result.batch)) {
        error = "udp: option " + quoted(option) + " given twice";
        return false;
      }
      if (bind) {
        if (!parse_udp_endpoint(option.substr(kBindKey.size()), result.bind, error)) {
          error = "udp: bind: " + error;
          return false;
        }
        seen_bind = true;
      } else if (option == kBatchKey) {
        result.batch = true;
      } else {
        error = "udp: unknown option " + quoted(option) + " (bind=HOST:PORT, batch)";
        return false;
      }
      at = next;
    }
    result.kind = CanBusSpec::Kind::udp;
    out = std::move(result);
    return true;
  }
  error = "unknown CAN bus " + quoted(spec) + "; expected udp:HOST:PORT[,bind=HOST:PORT][,batch] or socketcan:IFNAME";
  return false;
}

}  // namespace tensegrity::fw

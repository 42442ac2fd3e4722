// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a line on the operator console's local socket, read as the
// console reads a request and as a ground tool reads the console's reply
// (ground/operator_protocol.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "ground/operator_protocol.hpp"

namespace ground = tensegrity::ground;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  try {
    const ground::OperatorRequest request = ground::decode_request(line);
    // What decodes must encode back to the same request.
    const ground::OperatorRequest again = ground::decode_request(ground::encode_request(request));
    if (again.kind != request.kind || again.endcap_mask != request.endcap_mask || again.timeout_s != request.timeout_s)
      __builtin_trap();
  } catch (const ground::OperatorLinkError&) {
  }
  try {
    (void)ground::decode_reply(line);
  } catch (const ground::OperatorLinkError&) {
  }
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/node_log.hpp"

#include <cstdarg>
#include <cstdio>

namespace tensegrity::fw::comms {

void NodeLog::operator()(const char* format, ...) const {
  if (!enabled_) return;
  char text[400];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  std::fprintf(stderr, "endcap %d: %s\n", endcap_id_, text);
}

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// The end cap node's log: one line per event to stderr ("endcap N: ..."), or
// nothing when the node was configured quiet. Shared by the node's parts.
#pragma once

namespace tensegrity::fw::comms {

class NodeLog {
 public:
  NodeLog(int endcap_id, bool enabled) : endcap_id_(endcap_id), enabled_(enabled) {}
  void operator()(const char* format, ...) const __attribute__((format(printf, 2, 3)));

 private:
  int endcap_id_;
  bool enabled_;
};

}  // namespace tensegrity::fw::comms

// SPDX-License-Identifier: Apache-2.0
// Names of the control loop's events, for the log.
#include "firmware/app/control_loop.hpp"

namespace tensegrity::fw::app {

const char* to_string(AppEventKind kind) {
  switch (kind) {
    case AppEventKind::bring_up_done: return "bring-up done";
    case AppEventKind::bring_up_failed: return "bring-up failed";
    case AppEventKind::fault_latched: return "fault latched";
    case AppEventKind::fault_cleared: return "fault cleared";
    case AppEventKind::table_accepted: return "table accepted";
    case AppEventKind::table_rejected: return "table rejected";
    case AppEventKind::table_swapped: return "table swapped in";
    case AppEventKind::started: return "started";
    case AppEventKind::start_refused: return "start refused";
    case AppEventKind::stopped: return "stopped";
    case AppEventKind::master_event: return "CANopen";
  }
  return "unknown";
}

}  // namespace tensegrity::fw::app

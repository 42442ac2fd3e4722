// SPDX-License-Identifier: Apache-2.0
// The end cap program's log lines (stderr, "endcap N: ..."), for the housekeeping
// thread: never called from the control loop.
#pragma once

#include <string>

#include "firmware/app/control_loop.hpp"

namespace tensegrity::fw::app {

void set_log_endcap_id(int id);
void log_line(const char* format, ...) __attribute__((format(printf, 1, 2)));
void log_event(const AppEvent& event);
void log_status(const LoopStatus& status);

}  // namespace tensegrity::fw::app

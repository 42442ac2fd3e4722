// SPDX-License-Identifier: Apache-2.0
#include "firmware/endcap/endcap_log.hpp"

#include <cstdarg>
#include <cstdio>

#include "firmware/drivers/emcy.hpp"

namespace tensegrity::fw::app {
namespace {
int g_id = 0;
}  // namespace

void set_log_endcap_id(int id) { g_id = id; }

void log_line(const char* format, ...) {
  char text[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  std::fprintf(stderr, "endcap %d: %s\n", g_id, text);
}

void log_event(const AppEvent& e) {
  const double t_s = static_cast<double>(e.time_ns) * 1e-9;
  switch (e.kind) {
    case AppEventKind::fault_latched:
    case AppEventKind::fault_cleared:
    case AppEventKind::start_refused:
      log_line("t=%.3f s %s: %s", t_s, to_string(e.kind), core::describe(e.cause));
      break;
    case AppEventKind::table_accepted:
    case AppEventKind::table_rejected:
      log_line("t=%.3f s %s: %s", t_s, to_string(e.kind), core::describe(e.table_error));
      break;
    case AppEventKind::bring_up_failed: log_line("t=%.3f s bring-up failed: %s (retrying)", t_s, e.text.data()); break;
    case AppEventKind::master_event:
      // SDO results are bring-up chatter; bring-up outcomes are the loop's own events.
      if (e.master_kind == canopen::MasterEventKind::sdo_finished ||
          e.master_kind == canopen::MasterEventKind::bring_up_done ||
          e.master_kind == canopen::MasterEventKind::bring_up_failed) {
        break;
      }
      if (e.master_kind == canopen::MasterEventKind::emcy) {
        log_line("t=%.3f s node %u: EMCY 0x%04X (%s)", t_s, static_cast<unsigned>(e.node_id),
                 static_cast<unsigned>(e.emcy_code), canopen::emcy_error_text(e.emcy_code));
      } else {
        log_line("t=%.3f s node %u: %s", t_s, static_cast<unsigned>(e.node_id), to_string(e.master_kind));
      }
      break;
    default: log_line("t=%.3f s %s", t_s, to_string(e.kind)); break;
  }
}

void log_status(const LoopStatus& s) {
  log_line("t=%.1f s cycles %llu overruns %llu late %llu cycle p50 %.1f us p99 %.1f us max %.1f us, %s%s%s",
           static_cast<double>(s.time_ns) * 1e-9, static_cast<unsigned long long>(s.cycles),
           static_cast<unsigned long long>(s.overruns), static_cast<unsigned long long>(s.late_wakeups),
           static_cast<double>(s.cycle_window.p50_ns) / 1e3, static_cast<double>(s.cycle_window.p99_ns) / 1e3,
           static_cast<double>(s.cycle_window.max_ns) / 1e3,
           s.mode == core::Mode::running ? "running" : (s.mode == core::Mode::faulted ? "faulted" : "idle"),
           s.fault != core::FaultCause::none ? ": " : "",
           s.fault != core::FaultCause::none ? core::describe(s.fault) : "");
  if (s.drain_limited_cycles > 0) {
    log_line("bus drain hit its per-cycle limit in %llu cycles (a flooded bus)",
             static_cast<unsigned long long>(s.drain_limited_cycles));
  }
}

}  // namespace tensegrity::fw::app

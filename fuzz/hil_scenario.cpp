// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a HIL fault scenario (hil/scenario.hpp), the same bytes read both
// as a scenario file (`tensegrity hil --scenario FILE`) and as one `--fault` option.
// Oracle: only HilError escapes, and every event let through, and then passed by the
// check against the hardware robot (robots/superball.json), is one the fault injector can act on as written.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "hil/hil_error.hpp"
#include "hil/scenario.hpp"
#include "robot/robot.hpp"

namespace hil = tensegrity::hil;

namespace {

constexpr int kEndcaps = 12;

void require(bool ok) {
  if (!ok) std::abort();  // an event the parser should have refused
}

const tensegrity::sim::Robot& robot() {
  static const auto r = tensegrity::sim::load_robot(tensegrity::sim::robot_path_named("superball"));
  return r;
}

// Past check_scenario, a motor named is one the end cap has.
void check_motors(const hil::Scenario& s) {
  try {
    hil::check_scenario(s, robot());
  } catch (const hil::HilError&) {
    return;
  }
  for (const auto& ev : s.events) {
    if (ev.endcap >= 0 && ev.params.motor >= 0)
      require(static_cast<std::size_t>(ev.params.motor) < robot().cables_of(ev.endcap).size());
  }
}

// Stated here from what FaultInjector reads, not taken from the parser's own table:
// an oracle that shared it would pass whatever the table says.
bool takes_no_params(hil::FaultKind kind) {
  switch (kind) {
    case hil::FaultKind::drive_fault:
    case hil::FaultKind::drive_silent:
    case hil::FaultKind::release_spool:
    case hil::FaultKind::seize_spool:
    case hil::FaultKind::reboot_drive:
    case hil::FaultKind::drive_preoperational:
    case hil::FaultKind::load_cell_drift:
    case hil::FaultKind::drop_frames:
    case hil::FaultKind::corrupt_frames: return false;
    default: return true;
  }
}

void check(const hil::ScenarioEvent& ev) {
  require(std::isfinite(ev.time_s) && ev.time_s >= 0.0);
  require(ev.endcap == -1 ? hil::may_name_every_endcap(ev.fault) : ev.endcap >= 0 && ev.endcap < kEndcaps);
  require(ev.params.motor >= -1 && ev.params.motor <= 3);
  require(ev.params.probability >= 0.0 && ev.params.probability <= 1.0);
  require(std::isfinite(ev.params.duration_s) && ev.params.duration_s >= 0.0);
  require(std::isfinite(ev.params.n_per_s));
  if (takes_no_params(ev.fault)) {
    const hil::FaultParams none;
    require(ev.params.motor == none.motor && ev.params.code == none.code && ev.params.release == none.release &&
            ev.params.n_per_s == none.n_per_s && ev.params.probability == none.probability &&
            ev.params.duration_s == none.duration_s && ev.params.corrupt_kind == none.corrupt_kind);
  }
  require(!ev.describe().empty());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16 * 1024) return -1;  // scenario files are a few hundred bytes
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const hil::Scenario s = hil::parse_scenario(text, kEndcaps, "fuzz");
    for (const auto& ev : s.events) check(ev);
    require(std::is_sorted(s.events.begin(), s.events.end(),
                           [](const auto& a, const auto& b) { return a.time_s < b.time_s; }));
    check_motors(s);
  } catch (const hil::HilError&) {
  }
  try {
    const hil::ScenarioEvent ev = hil::parse_fault_option(text, kEndcaps);
    check(ev);
    check_motors(hil::Scenario{{ev}});
  } catch (const hil::HilError&) {
  }
  return 0;
}

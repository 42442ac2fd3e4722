// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a telemetry CSV as the view's replay reads it (view/replay_data.hpp)
// for the hardware robot (robots/superball.json), then the replay object the page gets.
// The reader takes a path (it streams files of 100 MB), so each input is written to a
// scratch file first.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "robot/robot.hpp"
#include "view/csv_table.hpp"
#include "view/replay_data.hpp"

namespace sim = tensegrity::sim;
namespace view = tensegrity::view;

namespace {

const sim::Robot& robot() {
  static const sim::Robot r = sim::load_robot(sim::robot_path_named("superball"));
  return r;
}

const std::filesystem::path& scratch_file() {
  static const std::filesystem::path path = [] {
    const std::filesystem::path base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
    return base / ("tensegrity-fuzz-replay-" + std::to_string(::getpid()) + ".csv");
  }();
  return path;
}

// Every frame kept is whole and in time order. Values need not be finite once kept
// as floats: a diverged simulation writes huge positions, which the page is given as
// null (json_numbers.hpp) rather than the file refused.
void check(const view::ReplayFrames& f) {
  const std::size_t n = f.frames();
  if (f.node_m.size() != n * static_cast<std::size_t>(f.nodes) * 3) std::abort();
  if (f.rest_length_m.size() != n * static_cast<std::size_t>(f.cables)) std::abort();
  if (f.tension_n.size() != n * static_cast<std::size_t>(f.cables)) std::abort();
  if (f.has_energy && f.energy_j.size() != n * 3) std::abort();
  for (std::size_t i = 1; i < n; ++i) {
    if (!(f.time_s[i] >= f.time_s[i - 1])) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::ofstream(scratch_file(), std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  std::vector<std::string> warnings;
  try {
    const view::ReplayFrames frames = view::load_replay_csv(scratch_file(), robot(), warnings);
    check(frames);
    (void)view::replay_json(frames, "fuzz");
  } catch (const view::InputError&) {
  }
  return 0;
}

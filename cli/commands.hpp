// SPDX-License-Identifier: Apache-2.0
#pragma once
// Each `tensegrity` subcommand adds itself to the app and runs from its callback.
// A callback reports failure by throwing CommandError (exit code and message).
#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

#include "core/exit_code.hpp"

namespace tensegrity::cli {

// `throw CommandError(ExitCode::usage, "--speed: must be ...")`: main prints the
// message and exits with the code's number. The code is named (core/exit_code.hpp),
// never a bare number, so every command's statuses stay one documented set.
class CommandError : public std::runtime_error {
 public:
  CommandError(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

void add_sim_command(CLI::App& app);
// `robustness`: a gait across a perturbation set (sim/analysis/robustness.hpp).
void add_robustness_command(CLI::App& app);
// `analyze`: Figures 10-12 of one episode (sim/analysis/).
void add_analyze_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_evolve_command(CLI::App& app);
// `gaits symmetries|transform|set`: the symmetry group's gaits (sim/symmetry.hpp).
void add_gaits_command(CLI::App& app);
// `drive`: steer a course of waypoints (ground/drive/).
void add_drive_command(CLI::App& app);
// `bench evolve`, added by add_bench_command.
void add_bench_evolve_command(CLI::App& bench);
// Ground tools over DDS (ground/): one file each.
void add_upload_command(CLI::App& app);
void add_start_command(CLI::App& app);
void add_stop_command(CLI::App& app);
void add_estop_command(CLI::App& app);
void add_clear_fault_command(CLI::App& app);
void add_status_command(CLI::App& app);
// `console`: the long-lived operator station (estop key, relays the tools' commands).
void add_console_command(CLI::App& app);
void add_record_command(CLI::App& app);
// `security init|check`: DDS Security keystores (ground/keystore.hpp).
void add_security_command(CLI::App& app);
// The HIL emulator (hil/): `hil`, and `bench hil` added by add_bench_command.
void add_hil_command(CLI::App& app);
void add_bench_hil_command(CLI::App& bench);
// `soak`: the HIL's chaos soak (hil/soak_run.hpp); needs the DDS link.
void add_soak_command(CLI::App& app);
// The web view (view/).
void add_view_command(CLI::App& app);

}  // namespace tensegrity::cli

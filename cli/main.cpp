// SPDX-License-Identifier: Apache-2.0
// `tensegrity`: the host program (simulate, benchmark, evolve, upload, HIL, ...).
#include <cstdio>
#include <exception>

#include "cli/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"tensegrity: SUPERball simulator, coevolution and ground tools"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tensegrity 0.1.0");
  tensegrity::cli::add_sim_command(app);
  tensegrity::cli::add_robustness_command(app);
  tensegrity::cli::add_analyze_command(app);
  tensegrity::cli::add_bench_command(app);
  tensegrity::cli::add_evolve_command(app);
  tensegrity::cli::add_gaits_command(app);
  tensegrity::cli::add_drive_command(app);
#ifdef TENSEGRITY_CLI_DDS
  tensegrity::cli::add_upload_command(app);
  tensegrity::cli::add_start_command(app);
  tensegrity::cli::add_stop_command(app);
  tensegrity::cli::add_estop_command(app);
  tensegrity::cli::add_clear_fault_command(app);
  tensegrity::cli::add_status_command(app);
  tensegrity::cli::add_console_command(app);
  tensegrity::cli::add_record_command(app);
  tensegrity::cli::add_security_command(app);
  tensegrity::cli::add_soak_command(app);
#endif
  tensegrity::cli::add_hil_command(app);
#ifdef TENSEGRITY_CLI_VIEW
  tensegrity::cli::add_view_command(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_status(tensegrity::parse_exit(app.exit(e)));
  } catch (const tensegrity::cli::CommandError& e) {
    std::fprintf(stderr, "tensegrity: %s\n", e.what());
    return exit_status(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tensegrity: error: %s\n", e.what());
    return exit_status(tensegrity::ExitCode::failure);
  }
  return exit_status(tensegrity::ExitCode::ok);
}

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The exit statuses of the project's programs (`tensegrity`, `endcap`), one set with
// names, so that scripts can tell a refused command from one that ran and failed.
// The values are the interface (docs/reference/tensegrity.md, "Exit codes"): never
// renumber one.
namespace tensegrity {

enum class ExitCode : int {
  ok = 0,             // done as asked
  failure = 1,        // it ran and did not succeed: a check failed, end caps did not confirm, a run failed
  usage = 2,          // refused before it ran: an option, a file or a configuration it cannot use
  checkpoint = 3,     // `evolve`: the checkpoint directory cannot be resumed or written
  mpi = 4,            // `evolve --mpi`: the MPI job failed (no MPI session, or a rank gave up)
  cannot_exec = 127,  // a child process could not run its program (the shell's code for it)
};

// The number the process exits with.
constexpr int exit_status(ExitCode code) { return static_cast<int>(code); }

// A command line the argument parser refused, or answered itself (--help, --version),
// from the status the parser gives (CLI11's `App::exit`: 0 for help and version,
// 100-127 by kind of error): usage for every error, since its message already names
// the option.
constexpr ExitCode parse_exit(int parser_status) { return parser_status == 0 ? ExitCode::ok : ExitCode::usage; }

}  // namespace tensegrity

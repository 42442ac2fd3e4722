// SPDX-License-Identifier: Apache-2.0
#pragma once
// What can be known about an MPI launch before (or without) initialising MPI: the
// launcher's environment variables and the CPUs this process may run on. Built with
// or without MPI, so that the `tensegrity` program can refuse a wrong launch with a
// clear message either way.
#include <optional>
#include <string>

namespace tensegrity::sim::evolve {

// True when this binary was built with TENSEGRITY_WITH_MPI.
bool mpi_built();

// The number of processes mpirun (Open MPI or MPICH's hydra, or srun with PMI/PMIx)
// started, read from the environment it gives each of them; 0 when the launcher
// does not say; nullopt when this process was not started by such a launcher.
std::optional<int> mpi_launch_size();

// The CPUs this process may run on (its affinity mask): mpirun binds each rank to
// one core by default when it starts two or fewer, so a rank's threads should
// follow this, not the machine's core count.
int usable_cpus();

// This binary's compiler, C library and CPU family, which the ranks of a run compare:
// the same source built or run with others may round differently.
std::string build_fingerprint();

}  // namespace tensegrity::sim::evolve

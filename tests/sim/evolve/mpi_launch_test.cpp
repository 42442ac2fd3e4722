// SPDX-License-Identifier: Apache-2.0
// What `evolve --mpi` checks before starting MPI: the launcher's environment, the
// CPUs a rank may use, the build the ranks compare.
#include "sim/evolve/mpi_launch.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace tensegrity::sim::evolve {
namespace {

TEST(MpiLaunch, SeesTheLaunchersEnvironment) {
  ::unsetenv("OMPI_COMM_WORLD_SIZE");
  ::unsetenv("PMI_SIZE");
  ::unsetenv("PMIX_SIZE");
  ::unsetenv("PMIX_RANK");
  EXPECT_FALSE(mpi_launch_size().has_value());
  ::setenv("OMPI_COMM_WORLD_SIZE", "3", 1);
  EXPECT_EQ(mpi_launch_size(), 3);
  ::setenv("OMPI_COMM_WORLD_SIZE", "junk", 1);
  EXPECT_FALSE(mpi_launch_size().has_value());
  ::unsetenv("OMPI_COMM_WORLD_SIZE");
  ::setenv("PMIX_RANK", "0", 1);
  EXPECT_EQ(mpi_launch_size(), 0);
  ::unsetenv("PMIX_RANK");
  EXPECT_GE(usable_cpus(), 1);
  EXPECT_NE(build_fingerprint().find("glibc"), std::string::npos);
}

}  // namespace
}  // namespace tensegrity::sim::evolve

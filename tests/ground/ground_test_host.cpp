// SPDX-License-Identifier: Apache-2.0
// A host that only publishes its heartbeat and serves time, until killed: the
// "host" a test kills to see what the end caps do without one.
//   ground_test_host DOMAIN
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "ground/station.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: ground_test_host DOMAIN\n");
    return 2;
  }
  tensegrity::ground::StationOptions options;
  options.domain = std::stoi(argv[1]);
  options.name = "ground_test_host";
  tensegrity::ground::Station station(options);
  std::printf("READY\n");
  std::fflush(stdout);
  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
}

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The sanitizer runs of CI, each a subset chosen to fit CI's time:
#   asan  AddressSanitizer + UndefinedBehaviorSanitizer on every unit-test
#         executable and the end cap's end-to-end tests (12 real `endcap` processes)
#   tsan  ThreadSanitizer on the threads that share memory: the control loop's
#         mailbox, the end cap's DDS node (end caps in comms_test_node processes
#         against ground participants) and the HIL's UDP hub
#   ci    what CI runs (scripts/test.sh), about 9-11 minutes on 2 cores: asan on the
#         firmware's unit tests (core, drivers, hal, app with its end-cap process
#         tests, mailbox, comms) and on the host's readers of outside input that run
#         without a simulator (robot and policy files, DDS types and QoS, keystore,
#         the ground's checks, the view's data and HTTP server), tsan on the mailbox
#         and the HIL's unit tests (hub)
# Usage: scripts/sanitize.sh [asan] [tsan] [ci]   (default: asan tsan)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
jobs="$(nproc)"
unit='format_tests|core_tests|test_drivers|test_hal|endcap_app_tests|mailbox_tests|comms_tests|msgs_tests|robot_tests|sim_tests|evolve_tests|hil_unit_tests'

run_asan() {
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j "$jobs" --target \
    format_tests core_tests test_drivers test_hal endcap_app_tests mailbox_tests comms_tests msgs_tests robot_tests sim_tests evolve_tests \
    hil_unit_tests ground_cli_tests
  ctest --preset asan -L "^($unit)\$"
  ctest --preset asan -R 'RealEndcaps|EndcapProcess'
}

firmware='format_tests|core_tests|test_drivers|test_hal|endcap_app_tests|mailbox_tests|comms_tests'
host='robot_tests|msgs_tests|ground_keystore_tests|ground_start_check_tests|view_test|view_server_test'

run_ci() {
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j "$jobs" --target format_tests core_tests test_drivers test_hal endcap_app_tests mailbox_tests \
    comms_tests robot_tests msgs_tests ground_keystore_tests ground_start_check_tests view_test view_server_test
  ctest --preset asan -L "^($firmware|$host)\$"
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j "$jobs" --target mailbox_tests hil_unit_tests
  ctest --preset tsan -L '^(mailbox_tests|hil_unit_tests)$'
}

run_tsan() {
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j "$jobs" --target mailbox_tests hil_unit_tests ground_dds_tests
  ctest --preset tsan -L '^(mailbox_tests|hil_unit_tests|ground_dds_tests)$'
}

for what in "${@:-asan tsan}"; do
  for w in $what; do
    start=$(date +%s)
    "run_$w"
    echo "sanitize: $w took $(( $(date +%s) - start )) s"
  done
done

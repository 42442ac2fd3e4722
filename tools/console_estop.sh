#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The secured emergency stop through a running `tensegrity console` against one from
# a fresh tool (`estop --no-console`): 12 end caps (comms_test_node, one process) on
# loopback, each estop followed by a clear-fault; docs/guide/security.md. Prints and writes
# OUT/estop.csv (mode, run, exit code, the tool's wall time, the last ack in ms).
#   tools/console_estop.sh [BUILD=build/default] [RUNS=10] [OUT=out/console-estop] [DOMAIN=190]
set -u
B=${1:-build/default}; N=${2:-10}; W=${3:-out/console-estop}; D=${4:-190}
T=$B/cli/tensegrity; NODE=$B/tests/firmware/comms/comms_test_node
rm -rf "$W"; mkdir -p "$W"; chmod 700 "$W"
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }'; }
"$T" security init "$W/ks" >/dev/null 2>&1 || { echo "console_estop: security init failed" >&2; exit 1; }
"$NODE" --domain "$D" --endcaps 0-11 --keystore "$W/ks" --quiet >"$W/nodes.out" 2>"$W/nodes.err" &
nodes=$!
trap 'kill $nodes ${console:-} 2>/dev/null' EXIT
until grep -q READY "$W/nodes.out"; do sleep 0.2; done
t0=$(now)
"$T" console --keystore "$W/ks" --domain "$D" --socket "$W/sock/c.sock" </dev/null >"$W/console.out" 2>"$W/console.err" &
console=$!
until grep -q 'hears 12 of 12' "$W/console.out"; do
  sleep 0.1
  kill -0 $console 2>/dev/null || { echo "console_estop: the console died" >&2; cat "$W/console.err" >&2; exit 1; }
done
echo "console_estop: the console heard all 12 end caps after $(since "$t0") s"
echo "mode,run,rc,wall_s,last_ack_ms" >"$W/estop.csv"
one() {  # mode run args...
  local mode=$1 run=$2; shift 2
  local s; s=$(now)
  "$T" estop --keystore "$W/ks" --domain "$D" "$@" >"$W/e.out" 2>"$W/e.err"; local rc=$?
  local wall; wall=$(since "$s")
  local last; last=$(awk '$2=="accepted" { if ($3 > m) m = $3 } END { print m + 0 }' "$W/e.out")
  echo "$mode,$run,$rc,$wall,$last" >>"$W/estop.csv"
  "$T" clear-fault --keystore "$W/ks" --domain "$D" --console "$W/sock/c.sock" >/dev/null 2>&1
  sleep 0.5
}
for i in $(seq 1 "$N"); do one console "$i" --console "$W/sock/c.sock"; done
for i in $(seq 1 $(( (N + 1) / 2 ))); do one fresh "$i" --no-console; done
cat "$W/estop.csv"

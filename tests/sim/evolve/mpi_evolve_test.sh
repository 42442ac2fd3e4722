#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `tensegrity evolve --mpi` end to end, one case per ctest test:
#   same       mpirun -np 3 (oversubscribed) gives the policy and curve of the threaded
#              run with the same seed, byte for byte; also with rank 0 only handing out
#   dead       a worker rank killed with SIGKILL mid-run ends the job (no hang), and
#              --resume under mpirun then finishes it exactly as the threaded run
#   hung       a worker rank stopped with SIGSTOP fails the run after --mpi-timeout
#              (10 s) with a message naming the rank
#   launch     --mpi outside mpirun, and mpirun -np 2 without --mpi, are refused
# Usage: mpi_evolve_test.sh CASE TENSEGRITY_BINARY
set -euo pipefail

case_name=$1
tensegrity=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/mpi_evolve_${case_name}.XXXXXX")
cleanup() {
  # Only what this script started: the mpirun job (if still there) and its ranks.
  if [[ -n "${job:-}" ]] && kill -0 "$job" 2>/dev/null; then
    for p in $(pgrep -P "$job" || true); do kill -CONT "$p" 2>/dev/null || true; kill -KILL "$p" 2>/dev/null || true; done
    kill -KILL "$job" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT

# What Open MPI needs in a container: running as root is refused unless confirmed;
# more ranks than cores needs --oversubscribe; ranks with several threads need
# --bind-to none (mpirun binds each rank to one core when it starts <= 2); and the
# shared-memory transport's single-copy path (CMA, ptrace) is often not allowed.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
mpirun_=(mpirun --oversubscribe --bind-to none)

# A short physics evolution: 4 teams a generation, 2 s episodes (10 s where the job
# must still be running when the test interferes).
duration=2
[[ $case_name == dead || $case_name == hung ]] && duration=10
evolve_args=(--period 1 --complexity 3 --population 4 --replace 2 --teams 4 --seed 9 --threads 1 --duration "$duration")

fail() { echo "FAIL: $*" >&2; exit 1; }

same_files() {  # DIR_A DIR_B
  cmp "$1/policy.json" "$2/policy.json" || fail "policies differ ($1, $2)"
  cmp "$1/curve.csv" "$2/curve.csv" || fail "curves differ ($1, $2)"
}

threaded() {  # DIR EPISODES
  "$tensegrity" evolve "${evolve_args[@]}" --episodes "$2" --out "$1/policy.json" --log "$1/curve.csv" > "$1/stdout"
}

# The PID of rank R of the job started as $job (mpirun starts local ranks itself).
rank_pid() {
  for p in $(pgrep -P "$job" || true); do
    if tr '\0' '\n' < "/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$1"; then echo "$p"; return; fi
  done
}

wait_for_file() {  # FILE SECONDS
  for _ in $(seq 1 $(( $2 * 10 ))); do [[ -e $1 ]] && return 0; sleep 0.1; done
  fail "$1 did not appear within $2 s"
}

# Waits for $job at most SECONDS; sets $status.
wait_job() {
  for _ in $(seq 1 $(( $1 * 10 ))); do
    if ! kill -0 "$job" 2>/dev/null; then wait "$job" && status=0 || status=$?; return 0; fi
    sleep 0.1
  done
  fail "the MPI job did not end within $1 s (hang)"
}

case $case_name in
  same)
    mkdir -p "$work/t" "$work/m" "$work/m0"
    threaded "$work/t" 12
    "${mpirun_[@]}" -np 3 "$tensegrity" evolve "${evolve_args[@]}" --episodes 12 --mpi \
      --checkpoint "$work/m/ckpt" --out "$work/m/policy.json" --log "$work/m/curve.csv" --json > "$work/m/stdout"
    same_files "$work/t" "$work/m"
    grep -q '"ranks": 3' "$work/m/stdout" || fail "summary does not report 3 ranks"
    # Rank 0 only hands out teams: the two other ranks evaluate everything.
    "${mpirun_[@]}" -np 3 "$tensegrity" evolve "${evolve_args[@]}" --episodes 12 --mpi --mpi-root-threads 0 \
      --out "$work/m0/policy.json" --log "$work/m0/curve.csv" > "$work/m0/stdout"
    same_files "$work/t" "$work/m0"
    cat "$work/m0/stdout"
    ;;
  dead)
    mkdir -p "$work/t" "$work/m"
    threaded "$work/t" 80
    "${mpirun_[@]}" -np 3 "$tensegrity" evolve "${evolve_args[@]}" --episodes 80 --mpi \
      --checkpoint "$work/m/ckpt" --out "$work/m/policy.json" --log "$work/m/curve.csv" \
      > "$work/m/stdout" 2> "$work/m/stderr" &
    job=$!
    wait_for_file "$work/m/ckpt/checkpoint.json" 120
    victim=$(rank_pid 1)
    [[ -n $victim ]] || fail "rank 1 not found"
    kill -KILL "$victim"
    wait_job 60
    [[ $status -ne 0 ]] || fail "the job succeeded although rank 1 was killed"
    [[ ! -e "$work/m/policy.json" ]] || fail "a policy was written by the broken run"
    echo "--- mpirun's report after rank 1 was killed (exit $status):"
    cat "$work/m/stderr"
    job=
    "${mpirun_[@]}" -np 3 "$tensegrity" evolve "${evolve_args[@]}" --episodes 80 --mpi \
      --checkpoint "$work/m/ckpt" --resume --out "$work/m/policy.json" --log "$work/m/curve.csv" > "$work/m/stdout"
    grep -q "(resumed)" "$work/m/stdout" || fail "the second run did not resume"
    same_files "$work/t" "$work/m"
    ;;
  hung)
    mkdir -p "$work/m"
    "${mpirun_[@]}" -np 3 "$tensegrity" evolve "${evolve_args[@]}" --episodes 800 --mpi --mpi-timeout 10 \
      --checkpoint "$work/m/ckpt" --out "$work/m/policy.json" --log "$work/m/curve.csv" \
      > "$work/m/stdout" 2> "$work/m/stderr" &
    job=$!
    wait_for_file "$work/m/ckpt/checkpoint.json" 120
    victim=$(rank_pid 2)
    [[ -n $victim ]] || fail "rank 2 not found"
    kill -STOP "$victim"
    wait_job 90
    [[ $status -ne 0 ]] || fail "the job succeeded although rank 2 was stopped"
    echo "--- report after rank 2 was stopped (exit $status):"
    cat "$work/m/stderr"
    grep -Eq "rank 2 .*(has returned nothing|took no job message) for 10 s" "$work/m/stderr" || fail "no message naming the silent rank"
    ;;
  launch)
    set +e
    out=$("$tensegrity" evolve "${evolve_args[@]}" --episodes 4 --mpi --out "$work/p.json" --log "$work/c.csv" 2>&1)
    status=$?
    set -e
    echo "$out"
    [[ $status -eq 2 ]] || fail "--mpi outside mpirun: exit $status, expected 2"
    grep -q "not started by mpirun" <<< "$out" || fail "--mpi outside mpirun: unclear message"
    set +e
    out=$("${mpirun_[@]}" -np 2 "$tensegrity" evolve "${evolve_args[@]}" --episodes 4 \
      --out "$work/p.json" --log "$work/c.csv" 2>&1)
    status=$?
    set -e
    echo "$out"
    [[ $status -ne 0 ]] || fail "mpirun without --mpi succeeded"
    grep -q "without --mpi" <<< "$out" || fail "mpirun without --mpi: unclear message"
    [[ ! -e "$work/p.json" ]] || fail "mpirun without --mpi wrote a policy"
    ;;
  *)
    fail "unknown case $case_name"
    ;;
esac
echo "PASS: $case_name"

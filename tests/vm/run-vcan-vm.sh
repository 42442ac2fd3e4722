#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs a static x86_64 test binary (test_socketcan_vcan) against a real Linux kernel
# with SocketCAN: boots Debian's amd64 kernel under qemu-system-x86_64 (TCG, no KVM)
# with a busybox initramfs that loads can, can-raw, can-dev and vcan, creates vcan0,
# runs the binary and powers off. Exits with the binary's exit code; 77 (ctest's
# SKIP_RETURN_CODE) when qemu-system, busybox-static or the kernel cannot be had.
#
# Usage: tests/vm/run-vcan-vm.sh [options] TEST_BINARY [ARGS for the binary...]
#   --cache DIR    kernel and initramfs cache (default: <repo>/build/vm-cache)
#   --timeout S    give up after S seconds (default 120)
#   --kernel VER   kernel ABI, e.g. 6.1.0-56-amd64 (default: the newest one in the
#                  cache, else the one linux-image-amd64 depends on)
#   --no-install   do not install missing Debian packages (then: skip)
# Environment: TENSEGRITY_VM_KERNEL (as --kernel), TENSEGRITY_VM_CACHE (as --cache).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cache="${TENSEGRITY_VM_CACHE:-$root/build/vm-cache}"
timeout_s=120
kernel="${TENSEGRITY_VM_KERNEL:-}"
install=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cache) cache="$2"; shift 2 ;;
    --timeout) timeout_s="$2"; shift 2 ;;
    --kernel) kernel="$2"; shift 2 ;;
    --no-install) install=0; shift ;;
    --) shift; break ;;
    -*) echo "run-vcan-vm: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
[[ $# -ge 1 ]] || { echo "usage: $0 [options] TEST_BINARY [ARGS...]" >&2; exit 2; }
binary="$(realpath "$1")"; shift
test_args=("$@")

skip() { echo "run-vcan-vm: SKIP: $*" >&2; exit 77; }
log() { echo "run-vcan-vm: $*" >&2; }

[[ -x "$binary" ]] || { echo "run-vcan-vm: no executable $binary" >&2; exit 2; }
if ! file -b "$binary" 2>/dev/null | grep -q 'x86-64.*statically linked\|x86-64.*static-pie'; then
  # Without `file`, trust the caller; otherwise insist on a static x86_64 binary.
  command -v file >/dev/null && { echo "run-vcan-vm: $binary is not a static x86_64 executable" >&2; exit 2; }
fi

# shellcheck source=tests/vm/vm-kernel.sh
source "$here/vm-kernel.sh"
vm_need_tools "$here/debian-packages-vm.txt" "$install"
work="$(mktemp -d "${TMPDIR:-/tmp}/vcan-vm.XXXXXX")"
cleanup() { [[ -n "${qpid:-}" ]] && kill "$qpid" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
vm_kernel "$cache" "$kernel" "$work/kernel" can can-raw can-dev vcan   # what SocketCAN over vcan needs
order=("${VM_ORDER[@]}")

# --- initramfs ------------------------------------------------------------------------
ird="$work/root"
vm_initramfs_root "$ird" "$work/kernel"
# Debug info only slows the VM's loading of the initramfs.
strip -o "$ird/test" "$binary" 2>/dev/null || cp "$binary" "$ird/test"
printf '%s\n' "${test_args[@]+"${test_args[@]}"}" >"$ird/test.args"

vm_write_init "$ird" <<'EOF'
mount -t tmpfs tmpfs /tmp
ok=1
for m in $(cat /modules/order); do
  insmod "/modules/$m" || { echo "vm: insmod $m failed"; ok=0; }
done
if [ $ok = 1 ]; then
  ip link add dev vcan0 type vcan && ip link set up vcan0 || { echo "vm: cannot create vcan0"; ok=0; }
fi
if [ $ok = 1 ]; then
  set --
  while IFS= read -r a; do [ -n "$a" ] && set -- "$@" "$a"; done < /test.args
  cd /tmp
  TENSEGRITY_VCAN_IF=vcan0 HOME=/tmp GTEST_COLOR=no /test "$@"
  rc=$?
else
  rc=125
fi
echo "TENSEGRITY-VM-RESULT rc=$rc"
sync
poweroff -f
EOF
vm_pack_initramfs "$ird" "$work/initrd.gz"

# --- boot -----------------------------------------------------------------------------
log "booting $VM_KERNEL with ${#order[@]} module(s): ${order[*]##*/}"
start=$(date +%s.%N)
out="$work/console.log"
set +e
timeout --kill-after=5 "$timeout_s" qemu-system-x86_64 -nographic -no-reboot -m 256 \
  -accel tcg -cpu max -smp 1 -net none -monitor none -serial stdio -display none \
  -kernel "$work/kernel/vmlinuz" -initrd "$work/initrd.gz" \
  -append 'console=ttyS0 panic=-1 quiet' </dev/null >"$out" 2>&1 &
qpid=$!
wait "$qpid"; qrc=$?
qpid=
set -e
end=$(date +%s.%N)
# The console carries the test's output; show it (without carriage returns).
tr -d '\r' <"$out" | sed -e 's/\x1b\[[0-9;?]*[a-zA-Z]//g' -e 's/\x1bc//g'
secs="$(awk -v a="$start" -v b="$end" 'BEGIN{printf "%.1f", b-a}')"
rc="$(tr -d '\r' <"$out" | sed -n 's/^TENSEGRITY-VM-RESULT rc=\([0-9]*\)$/\1/p' | tail -n1)"
if [[ -z "$rc" ]]; then
  if [[ $qrc -eq 124 || $qrc -eq 137 ]]; then
    echo "run-vcan-vm: FAILED: no result within ${timeout_s} s" >&2
  else
    echo "run-vcan-vm: FAILED: the VM ended (qemu exit $qrc) without a result" >&2
  fi
  exit 1
fi
log "VM boot + test: ${secs} s, test exit code $rc"
[[ "$rc" == 125 ]] && { echo "run-vcan-vm: FAILED: VM setup (modules or vcan0)" >&2; exit 1; }
exit "$rc"

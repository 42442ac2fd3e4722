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

# --- host tools --------------------------------------------------------------------
need_tools() {
  command -v qemu-system-x86_64 >/dev/null && [[ -x /bin/busybox ]] &&
    file -b /bin/busybox | grep -q 'statically linked' &&
    command -v cpio >/dev/null && command -v xz >/dev/null && command -v zstd >/dev/null
}
if ! need_tools && [[ $install -eq 1 && $(id -u) -eq 0 ]]; then
  "$root/scripts/setup-cross.sh" "$here/debian-packages-vm.txt" >&2 || true
fi
need_tools || skip "needs qemu-system-x86_64, busybox-static, cpio, xz and zstd (scripts/setup-cross.sh $here/debian-packages-vm.txt)"

# --- kernel: Debian's linux-image-<abi>, downloaded once into the cache ----------------
mkdir -p "$cache"
exec 9>"$cache/.lock"
flock 9   # parallel runs share one cache

# A kernel already in the cache wins (no apt query: it takes seconds here); else
# the one Debian's linux-image-amd64 currently depends on.
if [[ -z "$kernel" ]]; then
  kernel="$(cd "$cache" && ls -1d kernel-*/.complete 2>/dev/null |
    sed -n 's|^kernel-\(.*\)/\.complete$|\1|p' | sort -V | tail -n1 || true)"
fi
if [[ -z "$kernel" ]]; then
  kernel="$(apt-cache depends linux-image-amd64 2>/dev/null |
    sed -n 's/^ *Depends: linux-image-\([0-9].*-amd64\)$/\1/p' | head -n1 || true)"
fi
[[ -n "$kernel" ]] || skip "cannot tell which kernel to use (apt-get update, or --kernel ABI)"

kdir="$cache/kernel-$kernel"
moddir="$kdir/lib/modules/$kernel"
wanted=(can can-raw can-dev vcan)   # what SocketCAN over vcan needs

declare -A seen=()
order=()
dep_line() {  # the modules.dep line of module $1 (file name without .ko*)
  grep -E "(^|/)$1\.ko(\.xz|\.zst|\.gz)?:" "$moddir/modules.dep" | head -n1
}
resolve() {  # appends module $1's dependencies, then $1, to order (paths in moddir)
  local name="$1" line path dep
  [[ -n "${seen[$name]:-}" ]] && return 0
  seen[$name]=1
  line="$(dep_line "$name")"
  if [[ -z "$line" ]]; then
    # Built into the kernel: nothing to load.
    grep -qE "(^|/)$name\.ko$" "$moddir/modules.builtin" 2>/dev/null && return 0
    log "module $name not found in $moddir/modules.dep"; return 1
  fi
  path="${line%%:*}"
  for dep in ${line#*:}; do
    dep="$(basename "$dep")"; resolve "${dep%%.ko*}" || return 1
  done
  order+=("$path")
}

if [[ "$(cat "$kdir/.complete" 2>/dev/null)" != "${wanted[*]}" ]]; then
  log "fetching linux-image-$kernel (once; cached in $kdir)"
  rm -rf "$kdir" "$kdir.tmp" "$cache/dl"; mkdir -p "$cache/dl"
  if ! (cd "$cache/dl" && apt-get download -qq "linux-image-$kernel" >/dev/null 2>&1); then
    if [[ $(id -u) -eq 0 ]]; then apt-get update -qq >/dev/null 2>&1 || true; fi
    (cd "$cache/dl" && apt-get download -qq "linux-image-$kernel" >/dev/null 2>&1) ||
      { rm -rf "$cache/dl"; skip "apt-get download linux-image-$kernel failed"; }
  fi
  dpkg-deb -x "$cache"/dl/linux-image-"$kernel"_*.deb "$kdir.tmp"
  rm -rf "$cache/dl"
  mkdir -p "$kdir/lib"
  cp "$kdir.tmp/boot/vmlinuz-$kernel" "$kdir/vmlinuz"
  mv "$kdir.tmp/lib/modules" "$kdir/lib/modules"
  rm -rf "$kdir.tmp"
  # The package ships no modules.dep (its postinst runs depmod): make one.
  if [[ ! -f "$moddir/modules.dep" ]]; then
    command -v depmod >/dev/null || PATH="$PATH:/usr/sbin:/sbin"
    command -v depmod >/dev/null || { rm -rf "$kdir"; skip "needs depmod (Debian package kmod)"; }
    depmod -b "$kdir" "$kernel"
  fi
  for m in "${wanted[@]}"; do resolve "$m" || { rm -rf "$kdir"; skip "kernel $kernel lacks module $m"; }; done
  # Keep only the modules the VM loads (about 400 MB otherwise).
  keep="$(printf '%s\n' "${order[@]}")"
  (cd "$moddir" && find kernel -type f -name '*.ko*' | grep -vxF "$keep" | xargs -r rm -f)
  find "$moddir/kernel" -depth -type d -empty -delete
  echo "${wanted[*]}" >"$kdir/.complete"
else
  for m in "${wanted[@]}"; do resolve "$m" || skip "kernel $kernel lacks module $m"; done
fi
[[ -f "$kdir/vmlinuz" ]] || skip "kernel cache $kdir is incomplete"

# --- initramfs ------------------------------------------------------------------------
work="$(mktemp -d "${TMPDIR:-/tmp}/vcan-vm.XXXXXX")"
cleanup() { [[ -n "${qpid:-}" ]] && kill "$qpid" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
ird="$work/root"
mkdir -p "$ird"/{bin,sbin,usr/bin,usr/sbin,proc,sys,dev,tmp,modules}
cp /bin/busybox "$ird/bin/busybox"
: >"$ird/modules/order"
for path in "${order[@]}"; do
  base="$(basename "$path")"; out="$ird/modules/${base%%.ko*}.ko"
  case "$path" in   # the busybox insmod may lack decompression: decompress here
    *.ko.xz) xz -dc "$moddir/$path" >"$out" ;;
    *.ko.zst) zstd -qdc "$moddir/$path" >"$out" ;;
    *.ko.gz) gzip -dc "$moddir/$path" >"$out" ;;
    *) cp "$moddir/$path" "$out" ;;
  esac
  echo "${base%%.ko*}.ko" >>"$ird/modules/order"
done
# Debug info only slows the VM's loading of the initramfs.
strip -o "$ird/test" "$binary" 2>/dev/null || cp "$binary" "$ird/test"
printf '%s\n' "${test_args[@]+"${test_args[@]}"}" >"$ird/test.args"

cat >"$ird/init" <<'EOF'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev 2>/dev/null
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
chmod +x "$ird/init"
(cd "$ird" && find . | LC_ALL=C sort | cpio -o -H newc --quiet | gzip -1) >"$work/initrd.gz"

# --- boot -----------------------------------------------------------------------------
log "booting $kernel with ${#order[@]} module(s): ${order[*]##*/}"
start=$(date +%s.%N)
out="$work/console.log"
set +e
timeout --kill-after=5 "$timeout_s" qemu-system-x86_64 -nographic -no-reboot -m 256 \
  -accel tcg -cpu max -smp 1 -net none -monitor none -serial stdio -display none \
  -kernel "$kdir/vmlinuz" -initrd "$work/initrd.gz" \
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

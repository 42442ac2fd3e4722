#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Power cuts in the middle of the end cap's policy-store writes. Boots Debian's amd64
# kernel under qemu-system-x86_64 (TCG) with an ext4 disk (mkfs.ext4 defaults, the
# boards' data=ordered journal) on virtio-blk. Each boot first reads the store as
# the end cap boots (power_cut_guest verify), then writes record v+1 over v in a loop
# through the end cap's PolicyStore and FileStorage (power_cut_guest write); a
# seeded random delay after the first write began, qemu is SIGKILLed: the guest's
# page cache and anything it had not handed to the disk are gone, what the disk
# completed stays. The next boot replays the journal and reads the record: it must
# be the last acknowledged one (old) or the one in flight (new), whole; a record
# older than the last acknowledged, a mix or none is a failure, and so is a slot
# file that does not pass FileStorage's own check.
#
# Usage: tests/vm/power-cut.sh [options] POWER_CUT_GUEST
#   --cuts N         power cuts (default 100)
#   --seed S         seed of the cut delays (default 1)
#   --window MS      each cut lands uniformly in [0, MS) ms after the first write
#                    began (default 300: several whole writes on this machine)
#   --break MODE     a broken writer for the negative control: no-file-fsync,
#                    no-dir-fsync or no-fsync (default none: the end cap's code)
#   --mount OPTS     ext4 mount options (default: defaults)
#   --keep DIR       keep the consoles, the cut table (cuts.tsv) and the image in DIR
#   --cache DIR, --kernel VER, --no-install, --timeout S   as run-vcan-vm.sh
# Exits 0 when every cut left a whole old or new record, 1 otherwise, 77 (skip)
# when qemu-system, busybox-static, e2fsprogs or the kernel cannot be had.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cache="${TENSEGRITY_VM_CACHE:-$root/build/vm-cache}"
kernel="${TENSEGRITY_VM_KERNEL:-}"
cuts=100 seed=1 window_ms=300 brk=none mount_opts=defaults keep="" timeout_s=120 install=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cuts) cuts="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --window) window_ms="$2"; shift 2 ;;
    --break) brk="$2"; shift 2 ;;
    --mount) mount_opts="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    --cache) cache="$2"; shift 2 ;;
    --kernel) kernel="$2"; shift 2 ;;
    --timeout) timeout_s="$2"; shift 2 ;;
    --no-install) install=0; shift ;;
    -*) echo "power-cut: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
[[ $# -eq 1 ]] || { echo "usage: $0 [options] POWER_CUT_GUEST" >&2; exit 2; }
guest="$(realpath "$1")"
[[ -x "$guest" ]] || { echo "power-cut: no executable $guest" >&2; exit 2; }

skip() { echo "power-cut: SKIP: $*" >&2; exit 77; }
log() { echo "power-cut: $*" >&2; }

# shellcheck source=tests/vm/vm-kernel.sh
source "$here/vm-kernel.sh"
vm_need_tools "$here/debian-packages-vm.txt" "$install"
PATH="$PATH:/usr/sbin:/sbin"
if ! command -v mkfs.ext4 >/dev/null || ! command -v e2fsck >/dev/null; then
  skip "needs mkfs.ext4 and e2fsck (Debian package e2fsprogs)"
fi
# crc32c: ext4 asks the crypto API for it at mount time (a softdep insmod cannot see).
work="$(mktemp -d "${TMPDIR:-/tmp}/power-cut.XXXXXX")"
qpid=""
cleanup() { [[ -n "$qpid" ]] && kill -9 "$qpid" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
vm_kernel "$cache" "$kernel" "$work/kernel" virtio_pci virtio_blk ext4 crc32c_generic
out="${keep:-$work/out}"
mkdir -p "$out"

# --- the disk: record 1 written on the host by the same program, then mkfs -d ------
mkdir -p "$work/fs"
"$guest" "$work/fs/store" write --count 1 >/dev/null
img="$out/disk.img"
mkfs.ext4 -q -F -d "$work/fs" "$img" 64M >/dev/null

# --- initramfs: modules, the guest, an init that verifies then writes or stops ------
ird="$work/root"
vm_initramfs_root "$ird" "$work/kernel"
mkdir -p "$ird/mnt"
strip -o "$ird/guest" "$guest" 2>/dev/null || cp "$guest" "$ird/guest"
vm_write_init "$ird" <<'EOF'
for m in $(cat /modules/order); do insmod "/modules/$m" || echo "PC INSMODFAILED $m"; done
for w in $(cat /proc/cmdline); do
  case "$w" in pc.mode=*) mode=${w#*=} ;; pc.break=*) brk=${w#*=} ;; pc.mount=*) opts=${w#*=} ;; esac
done
i=0
while [ ! -b /dev/vda ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); done
if mount -t ext4 -o "$opts" /dev/vda /mnt; then
  /guest /mnt/store verify --marks /dev/ttyS0
  if [ "$mode" = write ]; then
    /guest /mnt/store write --break "$brk" --marks /dev/ttyS0
    echo "PC WRITEREXIT $?"
  fi
  umount /mnt && echo "PC UNMOUNTED"
else
  echo "PC MOUNTFAILED"
fi
poweroff -f
EOF
vm_pack_initramfs "$ird" "$work/initrd.gz"

# no_timer_check: on a loaded host TCG's timer sometimes misses the kernel's IO-APIC
# check, which then panics ("IO-APIC + timer doesn't work") before it reaches init.
boot() {  # boot MODE LOG: qemu in the background, its pid in qpid
  : >"$2"   # before the first poll, which may run before qemu's redirection
  qemu-system-x86_64 -nographic -no-reboot -m 256 -accel tcg -cpu max -smp 1 -net none \
    -monitor none -serial stdio -display none -kernel "$work/kernel/vmlinuz" -initrd "$work/initrd.gz" \
    -drive "file=$img,format=raw,if=virtio,cache=none,aio=threads" \
    -append "console=ttyS0 panic=-1 quiet no_timer_check pc.mode=$1 pc.break=$brk pc.mount=$mount_opts" \
    </dev/null >"$2" 2>&1 &
  qpid=$!
}

text() {  # console $1 without carriage returns and the firmware's terminal escapes
  tr -d '\r' <"$1" | sed -e 's/\x1b\[[0-9;?]*[a-zA-Z]//g' -e 's/\x1bc//g'
}

marks() {  # the complete "PC ..." lines of console $1 (a torn last line never happened)
  if [[ -z "$(tail -c1 "$1")" ]]; then text "$1"; else text "$1" | sed '$d'; fi | grep -a '^PC ' || true
}

wait_for() {  # wait_for LOG PATTERN: until the console has it; 1 if qemu ended first
  local deadline=$((SECONDS + timeout_s))
  # One grep a poll, on the raw console: the lines waited for never follow an escape,
  # and a heavier poll took CPU from the VM on a loaded machine.
  while ! grep -aq "$2" "$1"; do
    kill -0 "$qpid" 2>/dev/null || return 1
    ((SECONDS < deadline)) || return 1
    sleep 0.02
  done
}

stop_vm() { { kill -9 "$qpid" && wait "$qpid"; } 2>/dev/null || true; qpid=""; }

# boot_to_store MODE LOG BOOT: boots until the guest has read the store. A kernel that
# died before the guest ran (a TCG boot flake) left the disk untouched: boot again.
boot_to_store() {
  local try
  for try in 1 2 3; do
    boot "$1" "$2"
    wait_for "$2" '^PC RECORD' && return 0
    stop_vm
    if grep -aq '^PC ' "$2"; then text "$2" >&2; return 1; fi
    pc_retries=$((pc_retries + 1))
    log "boot $3: the kernel never reached the store ($(text "$2" | grep -a -m1 -i 'panic' || echo 'no panic line')); again"
    mv "$2" "$2.failed-$try"
  done
  return 1
}

RANDOM=$seed
pc_retries=0
printf 'cut\tdelay_ms\tlast_mark\tacked\tin_flight\trecord\twhole\toutcome\tslots\n' >"$out/cuts.tsv"
# shellcheck source=tests/vm/power-cut-judge.sh
source "$here/power-cut-judge.sh"
writer="the end cap's FileStorage"
[[ "$brk" == none ]] || writer="FileStorage broken: $brk"
log "kernel $VM_KERNEL, ext4 ($mount_opts), $writer, $cuts cuts, seed $seed"
start=$SECONDS
for ((i = 1; i <= cuts + 1; i++)); do
  console="$out/console-$i.log"
  mode="write"
  ((i <= cuts)) || mode=final
  boot_to_store "$mode" "$console" "$i" || { log "FAILED: boot $i did not read the store"; exit 1; }
  # This boot's verify judges the previous cut.
  if ((i > 1)); then judge $((i - 1)) "$(marks "$console")"; fi
  if [[ $mode == final ]]; then
    wait_for "$console" '^PC UNMOUNTED' || log "the last boot did not unmount cleanly"
    wait "$qpid" || true
    qpid=""
    break
  fi
  wait_for "$console" '^PC BEGIN' || { text "$console" >&2; log "FAILED: boot $i never began a write"; exit 1; }
  delay_us=$(((RANDOM * 32768 + RANDOM) % (window_ms * 1000)))
  sleep "$(printf '%d.%06d' $((delay_us / 1000000)) $((delay_us % 1000000)))"
  stop_vm   # the power cut
  note_cut "$i" "$delay_us" "$(marks "$console")"
done
fsck_out="$(e2fsck -fn "$img" 2>&1)" && fsck=clean || fsck="NOT clean: $(echo "$fsck_out" | tail -n 3 | tr '\n' ' ')"
summary "$((SECONDS - start))" "$fsck"

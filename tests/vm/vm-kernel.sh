# shellcheck shell=bash
# SPDX-License-Identifier: Apache-2.0
# Sourced by the VM tests (run-vcan-vm.sh, power-cut.sh): Debian's own amd64 kernel,
# downloaded once into a cache, and a busybox initramfs that loads the modules a
# test needs. The caller defines log MSG and skip MSG (exit 77) before sourcing.
#
#   vm_need_tools PACKAGE_LIST INSTALL   qemu-system, busybox-static, cpio, xz, zstd,
#                                        installed from PACKAGE_LIST when INSTALL=1 and root
#   vm_kernel CACHE KERNEL DEST MODULE...  copies the kernel to DEST/vmlinuz and the
#                                        modules (dependencies first) to DEST/modules,
#                                        sets VM_KERNEL (its ABI) and VM_ORDER (their paths)
#   vm_initramfs_root DIR DEST           busybox, /modules/*.ko and /modules/order in DIR
#   vm_write_init DIR <BODY              DIR/init: busybox's shell with /proc, /sys and
#                                        /dev mounted, then the test's BODY from stdin
#   vm_pack_initramfs DIR OUT            DIR as a gzip'd newc cpio archive
# The cache keeps only the modules some test asked for (about 400 MB otherwise);
# asking for one it lacks downloads the package again and keeps the union. A test
# copies what it boots while it holds the cache's lock, so that a refill for
# another test cannot pull the kernel from under its later boots.

vm_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"

vm_need_tools() {
  local list="$1" install="$2"
  _vm_have_tools() {
    command -v qemu-system-x86_64 >/dev/null && [[ -x /bin/busybox ]] &&
      file -b /bin/busybox | grep -q 'statically linked' &&
      command -v cpio >/dev/null && command -v xz >/dev/null && command -v zstd >/dev/null
  }
  if ! _vm_have_tools && [[ $install -eq 1 && $(id -u) -eq 0 ]]; then
    "$vm_root/scripts/setup-cross.sh" "$list" >&2 || true
  fi
  _vm_have_tools || skip "needs qemu-system-x86_64, busybox-static, cpio, xz and zstd (scripts/setup-cross.sh $list)"
}

_vm_dep_line() {  # the modules.dep line of module $1 (file name without .ko*)
  grep -E "(^|/)$1\.ko(\.xz|\.zst|\.gz)?:" "$VM_MODDIR/modules.dep" | head -n1
}

_vm_resolve() {  # appends module $1's dependencies, then $1, to VM_ORDER
  local name="$1" line path dep
  [[ -n "${_vm_seen[$name]:-}" ]] && return 0
  _vm_seen[$name]=1
  line="$(_vm_dep_line "$name")"
  if [[ -z "$line" ]]; then
    # Built into the kernel: nothing to load.
    grep -qE "(^|/)$name\.ko$" "$VM_MODDIR/modules.builtin" 2>/dev/null && return 0
    log "module $name not found in $VM_MODDIR/modules.dep"; return 1
  fi
  path="${line%%:*}"
  for dep in ${line#*:}; do
    dep="$(basename "$dep")"; _vm_resolve "${dep%%.ko*}" || return 1
  done
  VM_ORDER+=("$path")
}

_vm_resolve_all() {
  local m
  declare -gA _vm_seen=()
  VM_ORDER=()
  for m in "$@"; do _vm_resolve "$m" || return 1; done
}

# The newest kernel already in the cache wins (no apt query: it takes seconds
# here); else the one Debian's linux-image-amd64 currently depends on.
_vm_pick_kernel() {
  local cache="$1" k
  k="$(cd "$cache" && ls -1d kernel-*/.complete 2>/dev/null |
    sed -n 's|^kernel-\(.*\)/\.complete$|\1|p' | sort -V | tail -n1 || true)"
  if [[ -z "$k" ]]; then
    k="$(apt-cache depends linux-image-amd64 2>/dev/null |
      sed -n 's/^ *Depends: linux-image-\([0-9].*-amd64\)$/\1/p' | head -n1 || true)"
  fi
  echo "$k"
}

_vm_fetch_kernel() {  # downloads the package, keeps vmlinuz and the modules named
  local cache="$1" kdir="$VM_KDIR" keep
  shift
  log "fetching linux-image-$VM_KERNEL (once; cached in $kdir)"
  rm -rf "$kdir" "$kdir.tmp" "$cache/dl"; mkdir -p "$cache/dl"
  if ! (cd "$cache/dl" && apt-get download -qq "linux-image-$VM_KERNEL" >/dev/null 2>&1); then
    if [[ $(id -u) -eq 0 ]]; then apt-get update -qq >/dev/null 2>&1 || true; fi
    (cd "$cache/dl" && apt-get download -qq "linux-image-$VM_KERNEL" >/dev/null 2>&1) ||
      { rm -rf "$cache/dl"; skip "apt-get download linux-image-$VM_KERNEL failed"; }
  fi
  dpkg-deb -x "$cache"/dl/linux-image-"$VM_KERNEL"_*.deb "$kdir.tmp"
  rm -rf "$cache/dl"
  mkdir -p "$kdir/lib"
  cp "$kdir.tmp/boot/vmlinuz-$VM_KERNEL" "$kdir/vmlinuz"
  mv "$kdir.tmp/lib/modules" "$kdir/lib/modules"
  rm -rf "$kdir.tmp"
  # The package ships no modules.dep (its postinst runs depmod): make one.
  if [[ ! -f "$VM_MODDIR/modules.dep" ]]; then
    command -v depmod >/dev/null || PATH="$PATH:/usr/sbin:/sbin"
    command -v depmod >/dev/null || { rm -rf "$kdir"; skip "needs depmod (Debian package kmod)"; }
    depmod -b "$kdir" "$VM_KERNEL"
  fi
  _vm_resolve_all "$@" || { rm -rf "$kdir"; skip "kernel $VM_KERNEL lacks a module of: $*"; }
  keep="$(printf '%s\n' "${VM_ORDER[@]}")"
  (cd "$VM_MODDIR" && find kernel -type f -name '*.ko*' | grep -vxF "$keep" | xargs -r rm -f)
  find "$VM_MODDIR/kernel" -depth -type d -empty -delete
  echo "$*" >"$kdir/.complete"
}

vm_kernel() {
  local cache="$1" kernel="$2" dest="$3" m missing=0
  shift 3
  mkdir -p "$cache"
  # Parallel runs share one cache; the lock is held only while it is filled and read.
  exec 9>"$cache/.lock"
  flock 9
  [[ -n "$kernel" ]] || kernel="$(_vm_pick_kernel "$cache")"
  [[ -n "$kernel" ]] || { flock -u 9; skip "cannot tell which kernel to use (apt-get update, or --kernel ABI)"; }
  VM_KERNEL="$kernel"
  VM_KDIR="$cache/kernel-$kernel"
  VM_MODDIR="$VM_KDIR/lib/modules/$kernel"
  local kept=""
  [[ -f "$VM_KDIR/.complete" ]] && kept=" $(cat "$VM_KDIR/.complete") "
  for m in "$@"; do [[ "$kept" == *" $m "* ]] || missing=1; done
  if [[ -z "$kept" || $missing -eq 1 ]]; then
    # shellcheck disable=SC2086,SC2046  # module names: one word each
    _vm_fetch_kernel "$cache" $(printf '%s\n' $kept "$@" | awk '!seen[$0]++')
  fi
  _vm_resolve_all "$@" || { flock -u 9; skip "kernel $kernel lacks a module of: $*"; }
  [[ -f "$VM_KDIR/vmlinuz" ]] || { flock -u 9; skip "kernel cache $VM_KDIR is incomplete"; }
  _vm_copy_kernel "$dest"
  flock -u 9
}

_vm_copy_kernel() {
  local dest="$1" path base out
  mkdir -p "$dest/modules"
  cp "$VM_KDIR/vmlinuz" "$dest/vmlinuz"
  : >"$dest/modules/order"
  for path in "${VM_ORDER[@]}"; do
    base="$(basename "$path")"; out="$dest/modules/${base%%.ko*}.ko"
    case "$path" in   # the busybox insmod may lack decompression: decompress here
      *.ko.xz) xz -dc "$VM_MODDIR/$path" >"$out" ;;
      *.ko.zst) zstd -qdc "$VM_MODDIR/$path" >"$out" ;;
      *.ko.gz) gzip -dc "$VM_MODDIR/$path" >"$out" ;;
      *) cp "$VM_MODDIR/$path" "$out" ;;
    esac
    echo "${base%%.ko*}.ko" >>"$dest/modules/order"
  done
}

vm_initramfs_root() {
  local ird="$1" dest="$2"
  mkdir -p "$ird"/{bin,sbin,usr/bin,usr/sbin,proc,sys,dev,tmp}
  cp /bin/busybox "$ird/bin/busybox"
  cp -r "$dest/modules" "$ird/modules"
}

vm_write_init() {
  {
    cat <<'EOF'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev 2>/dev/null
EOF
    cat
  } >"$1/init"
  chmod +x "$1/init"
}

vm_pack_initramfs() {
  (cd "$1" && find . | LC_ALL=C sort | cpio -o -H newc --quiet | gzip -1) >"$2"
}

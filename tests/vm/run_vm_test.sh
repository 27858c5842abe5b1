#!/usr/bin/env bash
# Runs the drivers' device tests (and the onboard loop over vcan) inside a small qemu VM that
# boots Debian's own kernel, because the build machine's kernel has no vcan, uhid, gpio-sim or
# vivid. See docs/vm.md.
#
#   tests/vm/run_vm_test.sh --bin-dir BUILD/bin [--phases "devices onboard"] [--timeout S]
#                           [--work-dir DIR] [--keep]
#
# Steps: fetch Debian's kernel package into a cache (apt-get download + dpkg-deb -x, no system
# install), pack a gzip-compressed initramfs (busybox, the modules with their dependencies,
# tests/vm/init.sh as /init, the test binaries, and -- read straight from the host into a second
# part -- the shared libraries ldd names), boot it with qemu-system-x86_64 (KVM when it works, else
# TCG), read the serial console and exit with the VM's status. The work files go to a new folder
# in --work-dir (default $TMPDIR or /tmp) and are removed afterwards. Exit 77 (ctest's
# SKIP_RETURN_CODE) when qemu, busybox, cpio, gzip or the kernel is missing; 1 when a test
# failed or the work folder's disk is too full; 2 on bad usage; 124 when the VM ran out of time.
#
# Environment: EPICHEAD_VM_CACHE (kernel cache, default ~/.cache/epichead/vm),
# EPICHEAD_VM_ACCEL (auto | kvm | tcg), EPICHEAD_VM_KERNEL_PKG (default: what
# linux-image-amd64 depends on), EPICHEAD_GPIO_SIM_KO (a gpio-sim.ko built for that kernel:
# Debian builds its kernels without CONFIG_GPIO_SIM, see docs/vm.md).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
bin_dir=""
phases="devices onboard"
timeout_s=240
keep=0
work_parent="${TMPDIR:-/tmp}"
skip() { echo "vm-test: SKIP: $*" >&2; exit 77; }
die() { echo "vm-test: $*" >&2; exit 2; }
log() { echo "vm-test: $*" >&2; }

while (($#)); do
  case "$1" in
    --bin-dir) bin_dir="${2:?}"; shift 2 ;;
    --phases) phases="${2:?}"; shift 2 ;;
    --timeout) timeout_s="${2:?}"; shift 2 ;;
    --work-dir) work_parent="${2:?}"; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done
[[ -n "$bin_dir" ]] || die "--bin-dir is required (the build's bin/ folder)"
[[ -x "$bin_dir/epichead_test_hw_devices" ]] || die "$bin_dir/epichead_test_hw_devices: not built"
[[ "$timeout_s" =~ ^[0-9]+$ ]] || die "--timeout must be whole seconds"
for phase in $phases; do
  case "$phase" in
    devices) ;;
    onboard) [[ -x "$bin_dir/epichead" ]] || die "$bin_dir/epichead: not built (needed by the onboard phase)" ;;
    *) die "unknown phase '$phase' (devices, onboard)" ;;
  esac
done

# --- tools the VM needs on the host --------------------------------------------------------
qemu="$(command -v qemu-system-x86_64 || true)"
[[ -n "$qemu" ]] || skip "qemu-system-x86_64 not installed (Debian package qemu-system-x86)"
busybox=/bin/busybox
[[ -x "$busybox" ]] && ! ldd "$busybox" >/dev/null 2>&1 || skip "no static /bin/busybox (Debian package busybox-static)"
for tool in cpio gzip dpkg-deb objcopy ldd timeout; do
  command -v "$tool" >/dev/null || skip "$tool not installed"
done

mkdir -p "$work_parent" || die "--work-dir $work_parent: cannot create it"
work="$(mktemp -d "$work_parent/epichead-vm.XXXXXX")"
cleanup() {
  if ((keep)); then log "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

# --- Debian's kernel, unpacked into a cache -------------------------------------------------
# apt-get download + dpkg-deb -x rather than installing linux-image-amd64: the host does not
# boot it, installing would run initramfs-tools and kernel hooks on a build machine, and an
# unprivileged user can fill the cache too.
cache="${EPICHEAD_VM_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/epichead/vm}"
kernel_pkg="${EPICHEAD_VM_KERNEL_PKG:-$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends:/{print $2; exit}' || true)}"
fetch_kernel() {
  local pkg="$1" dest="$cache/$1"
  [[ -f "$dest/.complete" ]] && return 0
  log "fetching $pkg into $cache"
  mkdir -p "$cache" "$work/deb"
  (cd "$work/deb" && timeout 300 apt-get download -q -o APT::Sandbox::User=root "$pkg" >&2) || return 1
  rm -rf "$dest.partial"
  dpkg-deb -x "$work/deb/"*.deb "$dest.partial" || return 1
  dpkg-deb -f "$work/deb/"*.deb Version >"$dest.partial/.version" || return 1
  local version
  version="$(ls "$dest.partial/lib/modules")"
  # The package ships no modules.dep (its postinst runs depmod); busybox's depmod writes one.
  "$busybox" depmod -b "$dest.partial" "$version" || return 1
  touch "$dest.partial/.complete"
  rm -rf "$dest" && mv "$dest.partial" "$dest"
  rm -rf "$work/deb"
}
if [[ -z "$kernel_pkg" ]] || ! fetch_kernel "$kernel_pkg"; then
  # Offline: any complete kernel already in the cache will do.
  kernel_pkg="$(ls -d "$cache"/linux-image-*/.complete 2>/dev/null | sort -V | tail -1 | xargs -r dirname | xargs -r basename || true)"
  [[ -n "$kernel_pkg" ]] || skip "no Debian kernel: apt-get download linux-image-amd64's kernel failed and $cache is empty"
  log "using cached $kernel_pkg"
fi
kroot="$cache/$kernel_pkg"
kversion="$(ls "$kroot/lib/modules")"
vmlinuz="$kroot/boot/vmlinuz-$kversion"
[[ -r "$vmlinuz" ]] || skip "$vmlinuz missing"

# --- initramfs ------------------------------------------------------------------------------
root="$work/root"
# Merged /usr as on Debian 12: ldd prints /lib/... or /usr/lib/..., both must resolve.
mkdir -p "$root"/{bin,dev,proc,sys,tmp,run,etc,opt/epichead/bin,usr/lib/modules/"$kversion",usr/lib64}
ln -s usr/lib "$root/lib"
ln -s usr/lib64 "$root/lib64"
cp "$busybox" "$root/bin/busybox"
cp "$here/init.sh" "$root/init"
chmod 755 "$root/init"

# Modules: the wanted ones and everything modules.dep says they need.
wanted=(vcan can-raw uhid hid-generic vivid configfs)
moddep="$kroot/lib/modules/$kversion/modules.dep"
declare -A copied=()
copy_module() {  # $1: path relative to lib/modules/VERSION
  [[ -n "${copied[$1]:-}" ]] && return 0
  copied[$1]=1
  mkdir -p "$(dirname "$root/lib/modules/$kversion/$1")"
  cp "$kroot/lib/modules/$kversion/$1" "$root/lib/modules/$kversion/$1"
}
modules_loaded=()
for name in "${wanted[@]}"; do
  pattern="${name//[-_]/[-_]}"
  line="$(grep -E "/${pattern}\.ko(\.xz|\.zst)?:" "$moddep" | head -1 || true)"
  if [[ -z "$line" ]]; then
    # Built into the kernel (configfs on some configs) or not built at all.
    grep -qE "/${pattern}\.ko" "$kroot/lib/modules/$kversion/modules.builtin" || log "warning: module $name not in $kernel_pkg"
    continue
  fi
  for path in ${line/:/ }; do copy_module "$path"; done
  modules_loaded+=("$name")
done
require_devices="vcan,vivid,uhid"
# gpio-sim: Debian does not build it, so it is built once per kernel into the cache (see
# build_gpio_sim.sh). Without it the gpio-sim test case skips and says so.
gpio_sim_ko="${EPICHEAD_GPIO_SIM_KO:-$kroot/gpio-sim-vm.ko}"
if [[ ! -r "$gpio_sim_ko" && -z "${EPICHEAD_GPIO_SIM_KO:-}" ]]; then
  log "building gpio-sim for $kversion (once; log in $kroot/gpio-sim-build.log)"
  "$here/build_gpio_sim.sh" "$kversion" "$(cat "$kroot/.version" 2>/dev/null || echo unknown)" "$gpio_sim_ko" \
    >"$kroot/gpio-sim-build.log" 2>&1 || log "warning: gpio-sim build failed (see $kroot/gpio-sim-build.log): its test will skip"
fi
if [[ -r "$gpio_sim_ko" ]]; then
  mkdir -p "$root/lib/modules/$kversion/extra"
  cp "$gpio_sim_ko" "$root/lib/modules/$kversion/extra/gpio-sim.ko"
  copied[extra/gpio-sim.ko]=1
  modules_loaded+=(gpio-sim)
  require_devices+=",gpio-sim"
fi
cp "$kroot/lib/modules/$kversion"/modules.{order,builtin,builtin.modinfo} "$root/lib/modules/$kversion/"
"$busybox" depmod -b "$root" "$kversion"

# Binaries without debug sections (smaller cpio, faster unpacking). The libraries they load are
# not copied: OpenCV's video and image codecs alone pull in some 300 MB of libraries, and a copy
# plus the archive made of it once filled a CI machine's /tmp. They are listed here, each under
# its folder's real path (/lib is a link to usr/lib on merged /usr, made in the root above), and
# read straight from the host into the archive's second part below.
declare -A libs=()
add_binary() {
  local src="$1" dest="$root/opt/epichead/bin/$(basename "$1")"
  objcopy --strip-debug "$src" "$dest"
  local lib dir
  while read -r lib; do
    dir="$(realpath "$(dirname "$lib")")"
    libs["${dir#/}/$(basename "$lib")"]=1
    mkdir -p "$root$dir"
  done < <(ldd "$src" | awk '/=> \//{print $3} /^\t\/[^ ]+ \(/{print $1}')
}
add_binary "$bin_dir/epichead_test_hw_devices"
if [[ " $phases " == *" onboard "* ]]; then
  command -v jq >/dev/null || skip "jq not installed (the onboard phase checks replay's JSON with it)"
  add_binary "$bin_dir/epichead"
  add_binary "$(command -v jq)"
  cp "$here/onboard_phase.sh" "$root/etc/"
  mkdir -p "$root/etc/onboard"
  cp "$here/onboard/"* "$root/etc/onboard/"
  # The tracker's model file; the simulator's scenarios and scenes are built into the program.
  cp "$repo/sim/scenes/mockup_walk.cao" "$root/etc/onboard/model.cao"
fi

cat >"$root/etc/vm-test.conf" <<EOF
MODULES="${modules_loaded[*]}"
PHASES="$phases"
REQUIRE_DEVICES="$require_devices"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
EOF
# Two gzip-compressed archives one after the other, as the kernel accepts them: the root with the
# folders, then the libraries read from the host (-L: a library's content, not the link ldd
# found). Compressed, they are half the size; unpacking them costs the VM no measurable time.
lib_mb="$(cd / && printf '%s\n' "${!libs[@]}" | xargs du -bL | awk '{s += $1} END {print int(s / 1048576)}')"
root_mb="$(du -sm "$root" | cut -f1)"
need_mb=$(((lib_mb + root_mb) / 2 + 50))
free_mb="$(df -Pm "$work" | awk 'NR==2{print $4}')"
if ((free_mb < need_mb)); then
  log "FAILED: $work has ${free_mb} MB free; the initramfs needs about ${need_mb} MB" \
      "(${root_mb} MB of binaries and modules and ${lib_mb} MB of libraries, compressed). Free some space or pass --work-dir."
  exit 1
fi
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) >"$work/initrd.cpio"
(cd / && printf '%s\n' "${!libs[@]}" | sort | cpio -o -H newc -L --quiet | gzip -1) >>"$work/initrd.cpio"
log "initramfs $(du -m "$work/initrd.cpio" | cut -f1) MB (${root_mb} MB of binaries and modules and ${lib_mb} MB of" \
    "${#libs[@]} libraries before compression), kernel $kversion, modules: ${modules_loaded[*]}"

# --- boot ------------------------------------------------------------------------------------
# KVM when /dev/kvm is usable and a probe boot works (nested KVM often is not), else TCG.
accel="${EPICHEAD_VM_ACCEL:-auto}"
if [[ "$accel" == auto ]]; then
  accel=tcg
  if [[ -r /dev/kvm && -w /dev/kvm ]] &&
     timeout 20 "$qemu" -accel kvm -cpu host -M pc -m 128 -display none -nodefaults -serial stdio \
       -no-reboot -kernel "$vmlinuz" -append "console=ttyS0 panic=-1 quiet" 2>/dev/null |
       grep -q "Kernel panic"; then
    accel=kvm
  fi
fi
case "$accel" in
  kvm) cpu=(-accel kvm -cpu host) ;;
  tcg) cpu=(-accel tcg,thread=multi -cpu max) ;;
  *) die "EPICHEAD_VM_ACCEL must be auto, kvm or tcg" ;;
esac
log "booting with $accel, time limit ${timeout_s} s"
console="$work/console.log"
start_s=$SECONDS
set +e
timeout --kill-after=10 "$timeout_s" "$qemu" "${cpu[@]}" -M pc -smp 2 -m 2048 \
  -display none -nodefaults -no-reboot -serial stdio -nic none \
  -kernel "$vmlinuz" -initrd "$work/initrd.cpio" \
  -append "console=ttyS0 panic=-1 quiet loglevel=4 rdinit=/init epichead_accel=$accel" </dev/null | tee "$console"
qemu_rc=${PIPESTATUS[0]}
set -e
elapsed=$((SECONDS - start_s))
vm_status="$(tr -d '\r' <"$console" | sed -n 's/^vm: EPICHEAD_VM_STATUS=\([0-9]*\)$/\1/p' | tail -1)"
if [[ -z "$vm_status" ]]; then
  if ((qemu_rc == 124 || qemu_rc == 137)); then
    log "FAILED: the VM did not finish within ${timeout_s} s"
    exit 124
  fi
  log "FAILED: the VM stopped without a status line (qemu exit $qemu_rc)"
  exit 1
fi
log "VM finished in ${elapsed} s with status $vm_status"
exit "$vm_status"

#!/bin/busybox sh
# PID 1 of the device-test VM (tests/vm/run_vm_test.sh packs it as /init). It mounts the pseudo
# file systems, loads the modules the run script listed, makes the devices (vcan0, a gpio-sim
# bank), runs the phases and prints one status line the host waits for, then powers off.
# The host reads everything from the serial console; nothing is written back to the host.
/bin/busybox --install -s /bin
export PATH=/bin:/opt/epichead/bin HOME=/tmp TMPDIR=/tmp
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp
mount -t tmpfs tmpfs /run
mkdir -p /dev/pts && mount -t devpts devpts /dev/pts
exec </dev/console >/dev/console 2>&1
. /etc/vm-test.conf   # MODULES, PHASES, REQUIRE_DEVICES, ASAN_OPTIONS... written by the run script

say() { echo "vm: $*"; }
status=0
fail() { say "FAILED: $*"; status=1; }

say "kernel $(uname -r), $(nproc) cpu, $(awk '/MemTotal/{print $2 " kB"}' /proc/meminfo)"
for m in $MODULES; do
  modprobe "$m" || fail "modprobe $m"
done
if grep -q configfs /proc/filesystems; then
  mount -t configfs configfs /sys/kernel/config || fail "mount configfs"
fi
# vcan0 for the driver tests, vcan1 for the onboard loop (each phase gets a quiet bus).
for i in 0 1; do
  if [ -d /sys/module/vcan ]; then
    ip link add dev vcan$i type vcan && ip link set vcan$i up || fail "vcan$i"
  fi
done
# hidraw nodes come from hid-generic binding the uhid device; devtmpfs makes the node itself.
say "devices: $(ls /dev | grep -E '^(video|hidraw|uhid|gpiochip)' | tr '\n' ' ') $(ls /sys/class/net | tr '\n' ' ')"

run_phase() {
  name=$1; shift
  say "phase $name: $*"
  start=$(cut -d' ' -f1 /proc/uptime)
  "$@"
  rc=$?
  end=$(cut -d' ' -f1 /proc/uptime)
  say "phase $name: exit $rc after $(awk "BEGIN{print $end - $start}") s"
  [ $rc -eq 0 ] || fail "phase $name (exit $rc)"
}

for phase in $PHASES; do
  case $phase in
    devices)
      run_phase devices env EPICHEAD_REQUIRE_DEVICES="$REQUIRE_DEVICES" \
        epichead_test_hw_devices "[device]" --durations yes
      ;;
    onboard)
      run_phase onboard sh /etc/onboard_phase.sh
      ;;
  esac
done

say "EPICHEAD_VM_STATUS=$status"
sync
poweroff -f

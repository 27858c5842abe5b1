#!/usr/bin/env bash
# Builds the gpio-sim module for one of Debian's kernels, out of tree, from Debian's packages.
#
#   tests/vm/build_gpio_sim.sh KERNEL_RELEASE PACKAGE_VERSION OUT.ko
#   e.g.  6.1.0-56-amd64 6.1.192-2 ~/.cache/epichead/vm/linux-image-6.1.0-56-amd64/gpio-sim-vm.ko
#
# Why: Debian configures its kernels without CONFIG_GPIO_SIM, and without CONFIG_IRQ_SIM (the
# interrupt simulator gpio-sim raises its edge interrupts with), so the VM has no gpio-sim unless
# we build it. Both sources come from linux-source-X.Y of the same version as the kernel and are
# linked into one module, gpio-sim-vm.ko, against linux-headers-RELEASE. Nothing is installed:
# the packages are fetched with apt-get download and unpacked in a temporary folder.
#
# The one change to the kernel's source: irq_sim.c calls irq_to_desc(), which the kernel does not
# export to modules; it dispatches through generic_handle_irq() instead, which is exported and
# runs the same handle_simple_irq() flow handler irq_sim installs on each of its interrupts.
set -euo pipefail
(($# == 3)) || { sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
release="$1" version="$2" out="$3"
series="$(cut -d. -f1,2 <<<"$release")"         # 6.1
flavour_less="${release%-*}"                      # 6.1.0-56

work="$(mktemp -d "${TMPDIR:-/tmp}/epichead-gpio-sim.XXXXXX")"
trap 'rm -rf "$work"' EXIT
cd "$work"
pkgs=("linux-headers-$release=$version" "linux-headers-$flavour_less-common=$version"
      "linux-kbuild-$series=$version" "linux-source-$series=$version")
timeout 600 apt-get download -q -o APT::Sandbox::User=root "${pkgs[@]}" >&2
mkdir root
for deb in linux-headers-*.deb linux-kbuild-*.deb; do dpkg-deb -x "$deb" root; done
headers="$work/root/usr/src/linux-headers-$release"
# The flavour's Makefile includes the common tree by its installed path; point it here.
sed -i "s#/usr/src/linux-headers-$flavour_less-common#$work/root/usr/src/linux-headers-$flavour_less-common#" "$headers/Makefile"

# Three files out of the source tarball (xz: the whole stream is read, about 10 s).
dpkg-deb --fsys-tarfile linux-source-"$series"_*.deb |
  tar -xO "./usr/src/linux-source-$series.tar.xz" | xz -dc |
  tar -x -C "$work" "linux-source-$series/drivers/gpio/gpio-sim.c" \
      "linux-source-$series/drivers/gpio/gpiolib.h" "linux-source-$series/kernel/irq/irq_sim.c"
mkdir module
cp "linux-source-$series/drivers/gpio/"{gpio-sim.c,gpiolib.h} "linux-source-$series/kernel/irq/irq_sim.c" module/
grep -q 'handle_simple_irq(irq_to_desc(irqnum));' module/irq_sim.c ||
  { echo "build_gpio_sim: irq_sim.c of $version no longer looks as expected; update this script" >&2; exit 1; }
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' module/irq_sim.c
printf 'obj-m := gpio-sim-vm.o\ngpio-sim-vm-y := gpio-sim.o irq_sim.o\n' >module/Kbuild
make -s -C "$headers" M="$work/module" modules >&2
mkdir -p "$(dirname "$out")"
cp module/gpio-sim-vm.ko "$out.partial" && mv "$out.partial" "$out"
echo "build_gpio_sim: built $out" >&2

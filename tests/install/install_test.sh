#!/usr/bin/env bash
# Installs a build tree into a fresh prefix and uses it as another project would: a CMake
# project (find_package(epichead), epichead::<module> targets) and a plain compile with
# pkg-config, each tracking the first frames of a sequence; then the installed program runs a
# built-in scenario away from the source tree.
# With the Python module built, it imports it from the prefix and tracks a frame.
# With --deb the prefix is the Debian package's (`./dev package`: CPack) unpacked: its fields are
# checked (version, the libraries section of deps/debian-packages.txt among its dependencies)
# and its /usr is used as above, and apt simulates installing it (`apt-get install --simulate`:
# it resolves the Depends against the machine's package lists and changes nothing). (Unpacked,
# not installed: installing needs root and would change the machine the tests run on.)
# With --system (root, on a machine you may change: a container, a VM, a fresh install) the
# package is installed for real with apt-get, the checks run against /usr, and it is purged at
# the end. It refuses to run when epichead is already installed. Not part of ./dev test.
# What it built and unpacked (about 1 GB with the sanitizers) is removed once it passes; the logs
# stay in WORK_DIR. A failing run leaves everything there to look at.
# Usage: tests/install/install_test.sh [--deb|--system] BUILD_DIR WORK_DIR SEQUENCE_DIR [CXXFLAGS [PYTHON_PRELOAD]]
#   CXXFLAGS: the flags the build tree's libraries need in a consumer (the sanitizers)
#   PYTHON_PRELOAD: LD_PRELOAD for python3 importing a sanitized module (the ASan runtime)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
deb=0 system=0
if [[ "${1:-}" == --deb ]]; then deb=1; shift; fi
if [[ "${1:-}" == --system ]]; then deb=1 system=1; shift; fi
if ((system)); then
  [[ $(id -u) == 0 ]] || { echo "install_test: --system installs the package with apt-get: run it as root" >&2; exit 1; }
  if dpkg-query -W -f='${Status}' epichead 2>/dev/null | grep -q 'install ok installed'; then
    echo "install_test: --system: epichead is already installed here; remove it first (apt-get purge epichead)" >&2
    exit 1
  fi
fi
build="$1" work="$2" seq="$3" flags="${4:-}" python_preload="${5:-}"
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
step() { echo "install_test: $*"; }

if ((deb)); then
  step "cpack -G DEB in $build, unpacked into $work/root"
  (cd "$build" && cpack -G DEB -B "$work/package") > "$work/cpack.log" 2>&1 || { cat "$work/cpack.log" >&2; exit 1; }
  package=$(compgen -G "$work/package/epichead_*.deb" | head -1 || true)
  [[ -n "$package" ]] || { echo "install_test: cpack made no epichead_*.deb in $work/package" >&2; exit 1; }
  # CPack's staging tree is a second copy of the installation: only the .deb is used from here on.
  rm -rf "$work/package/_CPack_Packages"
  dpkg-deb --field "$package" Package Version Depends > "$work/fields.txt"
  grep -q '^Package: epichead$' "$work/fields.txt" || { echo "install_test: $package is not named epichead" >&2; exit 1; }
  deb_version=$(sed -n 's/^Version: //p' "$work/fields.txt")
  depends=$(sed -n 's/^Depends: //p' "$work/fields.txt")
  # Every package of the libraries section is a dependency (the headers build against them).
  for p in $(awk '/^# == /{section=$3} section=="libraries" && !/^#/ && NF {print $1}' "$here/../../deps/debian-packages.txt"); do
    grep -qE "(^|, )$p( |,|\$)" <<< "$depends" || { echo "install_test: $package does not depend on $p (Depends: $depends)" >&2; exit 1; }
  done
  # The Python module is built for one Python: the package says which.
  if grep -q '^EPICHEAD_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then
    grep -qE "(^|, )python3 \(>= 3\.[0-9]+~\), python3 \(<< 3\.[0-9]+\)" <<< "$depends" ||
      { echo "install_test: $package does not pin the python3 its module is built for (Depends: $depends)" >&2; exit 1; }
  fi
  if command -v apt-get > /dev/null; then
    step "apt-get install --simulate $(basename "$package")"
    # Unmet or misspelt dependencies make apt refuse (exit 100) and name them.
    apt-get install --simulate -q "$package" > "$work/apt-simulate.log" 2>&1 ||
      { cat "$work/apt-simulate.log" >&2; echo "install_test: apt would not install $package" >&2; exit 1; }
    grep -q '^Inst epichead ' "$work/apt-simulate.log" ||
      { cat "$work/apt-simulate.log" >&2; echo "install_test: apt's simulation installs no epichead" >&2; exit 1; }
  else
    step "no apt-get on this machine: the package's installation is not simulated"
  fi
  if ((system)); then
    step "apt-get install $(basename "$package") (purged again at the end)"
    trap 'DEBIAN_FRONTEND=noninteractive apt-get purge -y -q epichead > "$work/apt-purge.log" 2>&1 || cat "$work/apt-purge.log" >&2' EXIT
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q "$package" > "$work/apt-install.log" 2>&1 ||
      { cat "$work/apt-install.log" >&2; echo "install_test: apt-get could not install $package" >&2; exit 1; }
    prefix=/usr
  else
    dpkg-deb -x "$package" "$work/root"
    rm -f "$package"
    prefix="$work/root/usr"
  fi
else
  step "cmake --install $build --prefix $prefix"
  cmake --install "$build" --prefix "$prefix" > "$work/install.log"
fi
for f in bin/epichead include/epichead/vision/model_tracker.h share/doc/epichead/LICENSE share/doc/epichead/copyright; do
  [[ -e "$prefix/$f" ]] || { echo "install_test: $prefix/$f was not installed" >&2; exit 1; }
done
# Debian's copyright file (DEP-5) names the licence.
grep -q '^License: BSD-3-Clause$' "$prefix/share/doc/epichead/copyright" ||
  { echo "install_test: $prefix/share/doc/epichead/copyright does not name BSD-3-Clause" >&2; exit 1; }
if ((system)); then
  config=$(dpkg -L epichead | grep '/epicheadConfig.cmake$' | head -1 || true)
  pc=$(dpkg -L epichead | grep '/epichead.pc$' | head -1 || true)
else
  config=$(find "$prefix" -name epicheadConfig.cmake | head -1)
  pc=$(find "$prefix" -name epichead.pc | head -1)
fi
[[ -n "$config" && -n "$pc" ]] || { echo "install_test: no epicheadConfig.cmake or epichead.pc under $prefix" >&2; exit 1; }

step "a CMake project: find_package(epichead)"
cmake -S "$here/consumer" -B "$work/cmake-consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" > "$work/consumer-configure.log"
cmake --build "$work/cmake-consumer" > "$work/consumer-build.log" 2>&1 || { cat "$work/consumer-build.log" >&2; exit 1; }
"$work/cmake-consumer/consumer" "$seq" 5

step "a plain compile: pkg-config --cflags --libs epichead"
if ((deb && !system)); then
  # The package's pkg-config file names /usr as its prefix: a copy names the unpacked root's.
  mkdir -p "$work/pkgconfig"
  sed "s|^prefix=.*|prefix=$prefix|" "$pc" > "$work/pkgconfig/epichead.pc"
  pc="$work/pkgconfig/epichead.pc"
fi
export PKG_CONFIG_PATH="$(dirname "$pc")"
# shellcheck disable=SC2046,SC2086
# (pkg-config gives OpenCV's headers as -I, not -isystem: their warnings go to the log.)
g++ -std=c++23 $flags "$here/consumer/consumer.cpp" -o "$work/pc-consumer" $(pkg-config --cflags --libs epichead) \
  > "$work/pc-build.log" 2>&1 || { cat "$work/pc-build.log" >&2; exit 1; }
"$work/pc-consumer" "$seq" 5
version=$(pkg-config --modversion epichead)

if grep -q '^EPICHEAD_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then
  step "the Python module: import epichead from the prefix"
  python_dir=$(grep '^EPICHEAD_PYTHON_INSTALL_DIR:' "$build/CMakeCache.txt" | cut -d= -f2- || true)
  python=$(grep '^Python_EXECUTABLE:' "$build/CMakeCache.txt" | cut -d= -f2- || true)
  compgen -G "$prefix/$python_dir/epichead*.so" > /dev/null ||
    { echo "install_test: no epichead*.so in $prefix/$python_dir" >&2; exit 1; }
  (cd "$work" && PYTHONPATH="$prefix/$python_dir" LD_PRELOAD="$python_preload" ASAN_OPTIONS=detect_leaks=0 "${python:-/usr/bin/python3}" -c "
import sys, epichead
assert epichead.__file__.startswith('$prefix'), epichead.__file__
seq = epichead.Sequence(sys.argv[1])
r = epichead.Tracker(seq.camera, seq.model).track(seq.read_frame(0), seq.init.pose)
print('install_test: python: epichead', epichead.__version__, 'frame 0', r.status)
assert r.status == 'tracked'
" "$seq")
fi

step "the installed program, away from the source tree"
cd "$work"
program_version=$("$prefix/bin/epichead" --version)
[[ "$program_version" == *"$version"* ]] ||
  { echo "install_test: the program says '$program_version', pkg-config '$version'" >&2; exit 1; }
"$prefix/bin/epichead" sim box_clutter --frames 2 --out "$work/sim" > /dev/null
[[ -f "$work/sim/frames/000001.png" ]] || { echo "install_test: the installed program simulated no frames" >&2; exit 1; }
if ((deb)); then
  [[ "$deb_version" == "$version" ]] || { echo "install_test: the package says version '$deb_version', pkg-config '$version'" >&2; exit 1; }
fi
cd /
if ((system)); then
  rm -rf "$work/package"
else
  rm -rf "${prefix%/usr}" "$work/package"
fi
rm -rf "$work/cmake-consumer" "$work/pc-consumer" "$work/sim"
step "ok (version $version; what it installed and built is removed, the logs are in $work)"

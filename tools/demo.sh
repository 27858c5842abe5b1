#!/usr/bin/env bash
# The main job run by `./dev demo`: the closed-loop hardware-in-the-loop run of the onboard loop
# (tracker, Kalman predictor, head controller) against the simulator's walking robot, then a
# replay of the CAN log it recorded.
set -euo pipefail
bin="$1"
shift || true
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$here/out/demo"
mkdir -p "$out"
"$bin" sim-run mockup_walk --out "$out" "$@"
"$bin" replay "$out/bus.log" --plot "$out/replay" > "$out/replay.txt"
echo "demo: summary $out/summary.json, plots $out/sim_run.png and $out/replay/, replay report $out/replay.txt"

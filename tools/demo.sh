#!/usr/bin/env bash
# The main job run by `./dev demo`. Until the closed-loop simulator lands (issue 9) it is the
# projection demo: the teabox model drawn over the first frame of the real teabox video.
set -euo pipefail
bin="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seq="$here/../shared/data/teabox"
out="$here/out/demo"
mkdir -p "$out"
if [[ ! -d "$seq" ]]; then
  echo "demo: $seq not found (the shared data sits beside the checkout)" >&2
  exit 1
fi
"$bin" project "$seq" --frame 0 --out "$out/teabox_overlay.png"
echo "demo: wrote $out/teabox_overlay.png"

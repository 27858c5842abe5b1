#!/usr/bin/env bash
# Detection when the object searched for is not in view (issue 23: "a wrong object in view
# yields no detection"): `epichead detect --model OTHER` on frames that show another object.
#   - simulated scenes, each seed a new scene (`epichead sim --seed N`): the box scenes
#     (box_clutter, mockup_walk) searched for the can, the round ones (can, bowl, lampshade)
#     for box_clutter's printed package; frames 0, 30 and 60 of each;
#   - box_cover with its own model, on frames where the board hides the package (80, 90, 100);
#   - the real tea box videos (../shared/data) searched for the can, every 10th frame.
# Counts the frames where detect reported "found" (a false detection), without and, on the
# simulated sequences, with the IMU's gravity (--imu on --object-up 0,0,1). Writes DIR/rows.tsv
# (one line per frame: set scene seed frame found support found_with_gravity) and DIR/section.md (the table in
# docs/detection.md). Rows already in DIR/rows are kept: an interrupted run resumes.
# Usage: tools/wrong_object_eval.sh [--seeds "101 ... 106"] [--jobs J] [--out DIR] [--bin PATH]
#                                   [--table-only]
# Needs jq.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/bin/epichead"
seeds="101 102 103 104 105 106"
jobs=$(nproc)
out="$here/out/wrong_object_eval"
shared="$here/../shared/data"
table_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --table-only) table_only=1; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "wrong_object_eval: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
command -v jq > /dev/null || { echo "wrong_object_eval: needs jq" >&2; exit 1; }
[[ -x "$bin" ]] || { echo "wrong_object_eval: no program at $bin (./dev build first, or --bin)" >&2; exit 1; }
mkdir -p "$out/rows" "$out/models" "$out/run"
export EPICHEAD_CACHE_DIR="$out/template_cache"

# The models searched for: the can's and the printed package's, as the simulator writes them.
for scene in can box_clutter; do
  [[ -s "$out/models/$scene.cao" ]] && continue
  "$bin" sim "$scene" --frames 1 --out "$out/models/$scene-seq" > /dev/null
  cp "$out/models/$scene-seq/model.cao" "$out/models/$scene.cao"
done

# detect_frames SET SCENE SEED SEQ MODEL FRAME...: one row per frame. With imu.csv (the
# simulated sequences) each frame is searched again with gravity and the object's up (both
# models stand on their z axis), as a robot with its IMU would.
detect_frames() {
  local set="$1" scene="$2" seed="$3" seq="$4" model="$5"
  shift 5
  local row="$out/rows/$set-$scene-$seed.tsv"
  [[ -s "$row" ]] && return 0
  local lines=()
  for f in "$@"; do
    local d="$out/run/$set-$scene-$seed-$f" found=0 found_g=-
    rm -rf "$d" "$d-gravity"
    local model_arg=()
    [[ -n "$model" ]] && model_arg=(--model "$model")
    if "$bin" detect "$seq" --frame "$f" "${model_arg[@]}" --out "$d" > "$d.log" 2>&1; then found=1; fi
    [[ -f "$d/detection.json" ]] || { echo "wrong_object_eval: detect failed on $seq frame $f (see $d.log)" >&2; return 1; }
    if [[ -f "$seq/imu.csv" ]]; then
      found_g=0
      if "$bin" detect "$seq" --frame "$f" "${model_arg[@]}" --imu on --object-up 0,0,1 --out "$d-gravity" \
           > "$d-gravity.log" 2>&1; then found_g=1; fi
    fi
    lines+=("$(printf '%s\t%s\t%s\t%s\t%s\t%s\t%s' "$set" "$scene" "$seed" "$f" "$found" "$(jq -r '.best.support // 0' "$d/detection.json")" "$found_g")")
  done
  printf '%s\n' "${lines[@]}" > "$row"
}

# sim_one SCENE SEED: a new scene of SCENE searched for a model that is not in it.
sim_one() {
  local scene="$1" seed="$2" seq="$out/seq/$1-$2"
  [[ -s "$out/rows/sim-$scene-$seed.tsv" ]] && return 0
  rm -rf "$seq"
  "$bin" sim "$scene" --out "$seq" --seed "$seed" --frames 61 > /dev/null
  local other
  case "$scene" in box_clutter|mockup_walk) other="$out/models/can.cao" ;; *) other="$out/models/box_clutter.cao" ;; esac
  detect_frames sim "$scene" "$seed" "$seq" "$other" 0 30 60
  rm -rf "$seq"
}

# cover_one SEED: box_cover's own model while the board hides the package.
cover_one() {
  local seed="$1" seq="$out/seq/box_cover-$1"
  [[ -s "$out/rows/cover-box_cover-$seed.tsv" ]] && return 0
  rm -rf "$seq"
  "$bin" sim box_cover --out "$seq" --seed "$seed" --frames 101 > /dev/null
  detect_frames cover box_cover "$seed" "$seq" "" 80 90 100
  rm -rf "$seq"
}
export -f detect_frames sim_one cover_one
export bin out

if ((!table_only)); then
  # The real videos first, one at a time: each builds its camera's templates once.
  for video in teabox teabox_left; do
    # The frame count, as detect's range error says it (a real sequence may be a video file).
    n=$("$bin" detect "$shared/$video" --frame 1000000 --out "$out/run/count" 2>&1 | sed -n 's/.*the sequence has \([0-9]*\) frames.*/\1/p' || true)
    [[ -n "$n" ]] || { echo "wrong_object_eval: cannot count the frames of $shared/$video" >&2; exit 1; }
    detect_frames real "$video" - "$shared/$video" "$out/models/can.cao" $(seq 0 10 $((n - 1)))
  done
  # One run of each model alone builds its templates; the rest read them, in parallel.
  sim_one box_clutter "${seeds%% *}"
  sim_one can "${seeds%% *}"
  cover_one "${seeds%% *}"
  for scene in box_clutter mockup_walk can bowl lampshade; do
    for seed in $seeds; do echo "sim_one $scene $seed"; done
  done | xargs -r -P "$jobs" -L 1 bash -c '"$0" "$@"'
  for seed in $seeds; do echo "cover_one $seed"; done | xargs -r -P "$jobs" -L 1 bash -c '"$0" "$@"'
fi
cat "$out"/rows/*.tsv | sort -k1,1 -k2,2 -k3,3n -k4,4n > "$out/rows.tsv"

# The table: per set and scene, frames searched, frames reported found (false detections),
# without and with gravity.
awk -F'\t' '
  { k = $1 "\t" $2; n[k]++; f[k] += $5; if ($3 != "-") s[k, $3] = 1
    if ($6 > top[k]) top[k] = $6
    if ($7 != "-") { ng[k]++; fg[k] += $7 } }
  END {
    print "| frames of | searched for | seeds | frames searched | reported found (false) | highest support | with gravity (IMU): reported found |"
    print "|---|---|---|---|---|---|---|"
    for (k in n) {
      split(k, p, "\t"); seeds = 0
      for (q in s) { split(q, r, SUBSEP); if (r[1] == k) seeds++ }
      what = p[1] == "cover" ? "its own package, hidden by the board" : (p[2] ~ /box_clutter|mockup_walk/ ? "the can" : (p[1] == "real" ? "the can" : "the printed package"))
      scene = p[1] == "real" ? p[2] " (real video)" : p[2]
      printf "| %s | %s | %s | %d | %d | %.2f | %s |\n", scene, what, (seeds ? seeds : "-"), n[k], f[k], top[k], (ng[k] ? fg[k] " of " ng[k] : "-")
    }
  }' "$out/rows.tsv" | { read -r h; read -r s; echo "$h"; echo "$s"; sort; } > "$out/section.md.tmp"
awk -F'\t' '{ n++; f += $5; if ($7 != "-") { ng++; fg += $7 } }
  END { printf "| **all** | | | %d | %d (%.1f %%) | | %d of %d (%.1f %%) |\n", n, f, 100 * f / n, fg, ng, ng ? 100 * fg / ng : 0 }' \
  "$out/rows.tsv" >> "$out/section.md.tmp"
mv "$out/section.md.tmp" "$out/section.md"
cat "$out/section.md"

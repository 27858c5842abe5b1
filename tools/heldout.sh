#!/usr/bin/env bash
# Held-out evaluation (issue 19): every scenario simulated on development seeds (the ones
# parameters may be tuned on) and on held-out seeds (never tuned on), each a new draw of the
# scene (`epichead sim --seed N`: background, light, material, path, occluders, placement),
# tracked by every mode with and without the IMU, and summarised as distributions.
# Writes DIR/rows.tsv (one row per run) and DIR/section.md (what tools/results.sh puts first in
# docs/results.md); each simulation's stderr goes to DIR/seq/<scenario>-<seed>.sim.log. On a
# terminal, a progress line on stderr (sequences done, time taken, time left: tools/progress.sh).
# Usage: tools/heldout.sh [--dev "1 2 3"] [--held "101 ... 110"] [--scenarios "a b"] [--frames N]
#                         [--modes "m1 m2"] [--object-up X,Y,Z] [--jobs J] [--out DIR]
#   --dev, --held   seed lists (defaults: 1 2 3 and 101..112)
#   --scenarios     default: every built-in scenario
#   --frames N      simulate only the first N frames (default: the scenario's own)
#   --modes         tracker modes (default: gradient epic epic+validation); the table then
#                   has rows for these only
#   --imu "on off"  which IMU settings to track with (default: both; "on" after a change
#                   that only the IMU path sees)
#   --object-up X,Y,Z  given to track: the object's up when told (every simulated object
#                   stands on its base with its model's z up: 0,0,1); default: learnt
#   --jobs J        sequences simulated and tracked at once (default: nproc)
# Environment: EPICHEAD_BIN, the program to run (default: build/bin/epichead of this checkout).
# Needs jq.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${EPICHEAD_BIN:-$here/build/bin/epichead}"  # another build: EPICHEAD_BIN=path
# shellcheck source=progress.sh
. "$here/tools/progress.sh"

# One scenario and seed: simulate, track every mode with and without the IMU, score. Rows:
# scenario seed set mode imu success success_2cm_2deg rot_med_deg transl_med_mm nis_mean nis_within nis_count
#   success_no_sym (IMU runs of a body of revolution: scored without removing the turn) fallback_frames
#   nees_count nees_mean nees_within (the vision poses' covariance against the truth: score --covariance)
one() {
  local out="$1" frames="$2" scenario="$3" seed="$4" set="$5"
  [[ "$frames" == all ]] && frames=""
  local seq="$out/seq/$scenario-$seed"
  if [[ ! -f "$seq/gt.csv" ]]; then
    rm -rf "$seq"
    mkdir -p "$out/seq"
    # Its stderr to a log beside the sequence: several run at once, and the terminal is the
    # progress line's.
    if ! "$bin" sim "$scenario" --out "$seq" --seed "$seed" ${frames:+--frames "$frames"} > /dev/null 2> "$seq.sim.log"; then
      echo "heldout: sim failed on $scenario seed $seed: $(tail -1 "$seq.sim.log")" >&2
      exit 1
    fi
  fi
  local rows="$out/rows/$scenario-$seed.tsv"
  : > "$rows.part"
  local imus=()
  for imu in ${HELDOUT_IMU:-off on}; do
    [[ "$imu" == off || -f "$seq/imu.csv" ]] && imus+=("$imu")
  done
  for mode in ${HELDOUT_MODES:-gradient epic epic+validation}; do
    for imu in "${imus[@]}"; do
      local dir="$out/track/$scenario-$seed/$mode-imu-$imu"
      mkdir -p "$dir"
      if ! "$bin" track "$seq" --out "$dir" --mode "$mode" --imu "$imu" ${HELDOUT_OBJECT_UP:+--object-up "$HELDOUT_OBJECT_UP"} \
        --every 0 --no-video > "$dir/log" 2>&1; then
        echo "heldout: track failed on $scenario seed $seed ($mode, imu $imu): $(tail -1 "$dir/log")" >&2
        continue
      fi
      # A body of revolution: the tracker names the axis whose turn edges cannot show; score
      # with it removed, and with the IMU also without (the gyro keeps the turn).
      local axis sym=()
      axis=$(jq -r 'if .free_turn_axis then (.free_turn_axis.direction_obj | map(tostring) | join(",")) else "" end' "$dir/report.json")
      [[ -n "$axis" ]] && sym=(--sym-axis "$axis")
      "$bin" score "$seq" "$dir/poses.csv" --json "${sym[@]}" > "$dir/score.json"
      # The vision covariance against the truth: the pose estimator's own poses (with the IMU
      # poses.csv holds the filter's).
      local vision_poses="$dir/poses.csv"
      [[ "$imu" == on ]] && vision_poses="$dir/vision_poses.csv"
      "$bin" score "$seq" "$vision_poses" --json "${sym[@]}" --covariance "$dir/vision_covariance.csv" > "$dir/score_covariance.json"
      local no_sym="-"
      if [[ -n "$axis" && "$imu" == on ]]; then
        "$bin" score "$seq" "$dir/poses.csv" --json > "$dir/score_no_sym.json"
        no_sym=$(jq -r '.success_rate * 100' "$dir/score_no_sym.json")
      fi
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$scenario" "$seed" "$set" "$mode" "$imu" \
        "$(jq -r '.success_rate * 100' "$dir/score.json")" "$(jq -r '.success_rate_2cm_2deg * 100' "$dir/score.json")" \
        "$(jq -r '.rotation_deg.median // "nan"' "$dir/score.json")" "$(jq -r '.translation_mm.median // "nan"' "$dir/score.json")" \
        "$(jq -r '.predictor.vision_nis.mean // "-"' "$dir/report.json")" \
        "$(jq -r '.predictor.vision_nis.within_95pct_bounds // "-"' "$dir/report.json")" \
        "$(jq -r '.predictor.vision_nis.count // 0' "$dir/report.json")" "$no_sym" \
        "$(jq -r '.fallback_frames // 0' "$dir/report.json")" \
        "$(jq -r '.covariance_consistency.count' "$dir/score_covariance.json")" \
        "$(jq -r '.covariance_consistency.mean // "nan"' "$dir/score_covariance.json")" \
        "$(jq -r '.covariance_consistency.within_95pct // "nan"' "$dir/score_covariance.json")" >> "$rows.part"
    done
  done
  mv "$rows.part" "$rows"
  echo "heldout: $scenario seed $seed ($set) done"
}

if [[ "${1:-}" == --one ]]; then
  shift
  one "$@"
  exit 0
fi

dev="1 2 3"
held="101 102 103 104 105 106 107 108 109 110 111 112"
scenarios=""
frames=""
jobs="$(nproc 2>/dev/null || echo 2)"
out="$here/out/heldout"
while (($#)); do
  case "$1" in
    --dev) dev="$2"; shift 2 ;;
    --held) held="$2"; shift 2 ;;
    --scenarios) scenarios="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --modes) export HELDOUT_MODES="$2"; shift 2 ;;
    --imu) export HELDOUT_IMU="$2"; shift 2 ;;
    --object-up) export HELDOUT_OBJECT_UP="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "heldout: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v jq >/dev/null || { echo "heldout: jq is missing (apt-get install jq)" >&2; exit 1; }
[[ -x "$bin" ]] || "$here/dev" build > /dev/null
[[ -x "$bin" ]] || { echo "heldout: $bin is not a program" >&2; exit 1; }
if [[ -z "$scenarios" ]]; then
  scenarios=$(ls "$here/sim/scenarios/"*.scn | xargs -n1 basename | sed 's/\.scn$//' | tr '\n' ' ')
fi
mkdir -p "$out/rows"
rm -f "$out/rows/"*.tsv
jobs_list() {
  for s in $scenarios; do
    for seed in $dev; do echo "$s $seed dev"; done
    for seed in $held; do echo "$s $seed held"; done
  done
}
# Each sequence's "done" line, and the progress line under them (in the pipeline's last stage,
# so that a failed run still fails the script through pipefail).
jobs_list | xargs -P "$jobs" -L 1 "$0" --one "$out" "${frames:-all}" | {
  progress_start heldout "$(jobs_list | wc -l)" sequences
  while IFS= read -r line; do
    progress_say "$line"
    progress_step
  done
  progress_end
}
cat "$out/rows/"*.tsv > "$out/rows.tsv"
"$here/tools/heldout_table.sh" "$out/rows.tsv" "$dev" "$held" > "$out/section.md"
echo "heldout: wrote $out/section.md ($(wc -l < "$out/rows.tsv") runs)"

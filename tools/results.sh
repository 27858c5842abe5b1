#!/usr/bin/env bash
# Regenerates docs/results.md: every tracking mode (and ViSP's tracker when it is installed) on
# every built-in simulated scenario and on the real teabox videos, with success rate, errors and
# ms per frame, and the trackable-speed sweep of tools/jerk_sweep.sh (with and without IMU).
# First, and leading docs/results.md: the held-out evaluation of tools/heldout.sh (every scenario
# on development and held-out seeds, each seed a new draw of the scene).
# Usage: tools/results.sh [--frames N] [--seeds N] [--out DIR] [--no-sweep] [--no-heldout]
#   --frames N   simulate only the first N frames of each scenario (default: the scenario's own)
#   --seeds N    also track with N-1 more RANSAC seeds (1..N-1) and give the success spread (default 5)
#   --out DIR    where sequences and tracker outputs go (default: out/results)
#   --no-sweep   leave the jerk sweep out (it simulates 36 short sequences)
#   --no-heldout leave the held-out evaluation out (it simulates 90 sequences; ~40 min on 2 cores)
#   --heldout-dir DIR  take the held-out section from an earlier `tools/heldout.sh --out DIR` run
#   --no-visp    do not install libvisp-dev for ViSP's rows
# Needs jq. ViSP's columns need libvisp-dev (the comparison program builds only with it).
# On a terminal, a progress line on stderr (tracker runs done, time taken, time left:
# tools/progress.sh); the held-out evaluation shows its own first.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=progress.sh
. "$here/tools/progress.sh"
frames=""
out="$here/out/results"
sweep=1
heldout=1
heldout_dir=""
visp_install=1
seeds=5
while (($#)); do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --no-sweep) sweep=0; shift ;;
    --no-heldout) heldout=0; shift ;;
    --heldout-dir) heldout_dir="$2"; shift 2 ;;
    --no-visp) visp_install=0; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "results: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v jq >/dev/null || { echo "results: jq is missing (apt-get install jq)" >&2; exit 1; }
# ViSP's tracker beside ours: install it when we can (root), and configure the build to see it.
if ! dpkg-query -W -f='${Status}' libvisp-dev 2>/dev/null | grep -q 'install ok installed'; then
  if ((visp_install)) && [[ $(id -u) -eq 0 ]]; then
    echo "results: installing libvisp-dev for the ViSP comparison"
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends libvisp-dev > /dev/null
    [[ -f "$here/build/CMakeCache.txt" ]] && cmake "$here/build" > /dev/null
  else
    echo "results: libvisp-dev is not installed (run as root to install it): no ViSP rows" >&2
  fi
fi
"$here/dev" build >/dev/null
bin="$here/build/bin/epichead"
visp="$here/build/bin/epichead-visp"
data="$here/../shared/data"
mkdir -p "$out"
if ((heldout)) && [[ -z "$heldout_dir" ]]; then
  heldout_dir="$out/heldout"
  "$here/tools/heldout.sh" --out "$heldout_dir" ${frames:+--frames "$frames"}
fi
rows="$out/rows.md"
: > "$rows"

# fmt FILE JQ_EXPR PRINTF_FORMAT: a number from a JSON file, or "–" when it is null (a tracker
# that lost every frame has no error statistics).
fmt() {
  local v
  v=$(jq -r "$2" "$1")
  if [[ "$v" == null || -z "$v" ]]; then printf '–'; else printf "$3" "$v"; fi
}

# spread RATE...: "median (min-max)" of success rates in percent, or the one rate.
spread() {
  if (($# < 2)); then printf '%.1f %%' "$1"; return; fi
  printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {
    m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
    printf "%.1f %% (%.1f-%.1f)", m, v[1], v[NR] }'
}

# row SEQ_LABEL TRACKER IMU OUT_DIR SCORE_JSON SPREAD
row() {
  local label="$1" tracker="$2" imu="$3" dir="$4" score="$5" spread="$6"
  local common
  common="$(fmt "$score" '.success_rate * 100' '%.1f %%') | $(fmt "$score" '.rotation_deg.median' '%.2f') | $(fmt "$score" '.translation_mm.median' '%.1f')"
  if jq -e '.corners' "$score" >/dev/null 2>&1 && [[ "$(jq -r '.against' "$score")" != "gt.csv" ]]; then
    # Real video: agreement with the peer's poses and hand-read corners.
    printf '| %s | %s | %s | %s | %s | %s px | %s |\n' "$label" "$tracker" "$imu" "$common" "$spread" \
      "$(jq -r '[.corners[] | if .present then (.rms_px * 10 | round / 10 | tostring) else "lost" end] | join(" / ")' "$score")" \
      "$(fmt "$dir/report.json" '.track_ms_median' '%.2f')" >> "$rows"
  else
    printf '| %s | %s | %s | %s | %s | %s losses | %s |\n' "$label" "$tracker" "$imu" "$common" "$spread" \
      "$(jq -r '.losses' "$score")" "$(fmt "$dir/report.json" '.track_ms_median' '%.2f')" >> "$rows"
  fi
}

# track_all LABEL SEQ_DIR SCORE_ARGS...
track_all() {
  local label="$1" seq="$2"; shift 2
  local imus=(off)
  [[ -f "$seq/imu.csv" ]] && imus=(off on)
  for mode in gradient epic epic+validation; do
    for imu in "${imus[@]}"; do
      local dir="$out/$label/$mode-imu-$imu"
      mkdir -p "$out/$label"
      progress_say "results: $label $mode imu $imu"
      # The IMU clock offset is estimated by the tracker (--imu-time-offset-s auto, the default).
      if ! "$bin" track "$seq" --out "$dir" --mode "$mode" --imu "$imu" --every 50 \
          > "$dir.log" 2>&1; then
        progress_clear
        echo "results: track failed on $label ($mode, imu $imu): $(tail -1 "$dir.log")" >&2
        progress_step
        continue
      fi
      "$bin" score "$seq" "$dir/poses.csv" --json "$@" > "$dir/score.json"
      # The same run with other RANSAC seeds: which pairs are drawn can decide a marginal
      # frame, and from there the rest of a sequence (docs/epic.md, sixth pass).
      local rates=("$(jq -r '.success_rate * 100' "$dir/score.json")")
      for ((k = 1; k < seeds; ++k)); do
        local sdir="$dir-seed$k"
        if "$bin" track "$seq" --out "$sdir" --mode "$mode" --imu "$imu" --every 0 --no-video --ransac-seed "$k" \
            > "$sdir.log" 2>&1; then
          "$bin" score "$seq" "$sdir/poses.csv" --json "$@" > "$sdir/score.json"
          rates+=("$(jq -r '.success_rate * 100' "$sdir/score.json")")
        fi
      done
      row "$label" "epichead $mode" "$imu" "$dir" "$dir/score.json" "$(spread "${rates[@]}")"
      progress_step
    done
  done
  if [[ -x "$visp" ]]; then
    for vmode in edges edges+klt; do
      local dir="$out/$label/visp-$vmode"
      mkdir -p "$out/$label"
      progress_say "results: $label ViSP $vmode"
      if "$visp" "$seq" --out "$dir" --mode "$vmode" --overlay-every 50 > "$dir.log" 2>&1; then
        "$bin" score "$seq" "$dir/poses.csv" --json "$@" > "$dir/score.json"
        row "$label" "ViSP $vmode" "off" "$dir" "$dir/score.json" "–"
      else
        progress_clear
        echo "results: ViSP failed on $label ($vmode): $(tail -1 "$dir.log")" >&2
      fi
      progress_step
    done
  fi
}

# Progress: one step per tracker and mode on a sequence (with its extra RANSAC seeds), and the
# line-selection runs. A simulated sequence has imu.csv (tracked with and without it); the real
# videos are checked.
scenarios=(mockup_walk box_clutter office_pan lampshade can bowl)
runs_per_imu=3
visp_runs=0
[[ -x "$visp" ]] && visp_runs=2
total=$(( ${#scenarios[@]} * (2 * runs_per_imu + visp_runs) + 3 ))
for real in teabox teabox_left; do
  imus=1
  [[ -f "$data/$real/imu.csv" ]] && imus=2
  total=$((total + imus * runs_per_imu + visp_runs))
done
progress_start results "$total" runs
for scenario in "${scenarios[@]}"; do
  seq="$out/seq/$scenario"
  if [[ ! -f "$seq/gt.csv" ]]; then
    progress_say "results: simulating $scenario"
    progress_clear  # sim draws its own progress line (on a terminal)
    rm -rf "$seq"
    "$bin" sim "$scenario" --out "$seq" ${frames:+--frames "$frames"} > /dev/null
  fi
  sym=()
  [[ "$scenario" == lampshade || "$scenario" == can || "$scenario" == bowl ]] && sym=(--sym-axis 0,0,1)
  track_all "$scenario" "$seq" "${sym[@]}"
done
track_all teabox "$data/teabox" --reference "$data/teabox/reference_visp.csv" \
  --corners "0:$data/teabox/corners_frame000.txt" --corners "38:$data/teabox/corners_frame038.txt"
track_all teabox_left "$data/teabox_left" --reference "$data/teabox_left/reference_visp.csv" \
  --corners "0:$data/teabox_left/corners_frame000.txt" --corners "120:$data/teabox_left/corners_frame120.txt"

# Line selection on mockup_walk (the paper's Figs. 18/19): which image line each mode picked for
# each edge, against the ground truth, and a close-up of the bottom-front stiffeners (three
# close parallel edges) in the frame where validation set right the most of them.
lines_section="$out/lines_section.md"
{
  echo "## Line selection: validation keeps close parallel edges apart (paper, Figs. 18/19)"
  echo
  echo "\`epichead score --lines\`: for each visible edge the candidate the mode selected (before the pose"
  echo "judged it) is right when both its end points lie within 3 px of the edge projected at the true"
  echo "pose and its direction within 3 deg. Crowded edges have another visible edge within 5 deg and 12 px"
  echo "in the image (the stiffeners, the T-truss, the plate seams)."
  echo
  echo "| sequence | mode | selections right | crowded edges right |"
  echo "|---|---|---|---|"
} > "$lines_section"
mw="$out/seq/mockup_walk"
zoom="100,300,440,150"
for mode in gradient epic epic+validation; do
  dir="$out/lines/$mode"
  mkdir -p "$dir"
  "$bin" track "$mw" --out "$dir" --mode "$mode" --every 5 --no-video --zoom "$zoom" > "$dir.log" 2>&1
  "$bin" score "$mw" "$dir/poses.csv" --lines "$dir/lines.csv" --json > "$dir/score.json"
  printf '| mockup_walk | %s | %.1f %% of %d | %.1f %% of %d |\n' "$mode" \
    "$(jq -r '.line_selection.right_rate * 100' "$dir/score.json")" "$(jq -r '.line_selection.selections' "$dir/score.json")" \
    "$(jq -r '.line_selection.crowded_right_rate * 100' "$dir/score.json")" \
    "$(jq -r '.line_selection.crowded_selections' "$dir/score.json")" >> "$lines_section"
  progress_step
done
progress_end
# The overlay frame (a multiple of 5) where validation has the most more crowded edges right.
pick=$(jq -n --slurpfile e "$out/lines/epic/score.json" --slurpfile v "$out/lines/epic+validation/score.json" '
  [$v[0].line_selection.crowded_right_by_frame | to_entries[] | select((.key | tonumber) % 5 == 0)
   | {f: (.key | tonumber), d: (.value[0] - ($e[0].line_selection.crowded_right_by_frame[.key][0] // 0))}]
  | max_by(.d) | .f // 0')
cp "$(printf '%s/lines/epic/overlay_%06d.png' "$out" "$pick")" "$here/docs/fig18_epic.png"
cp "$(printf '%s/lines/epic+validation/overlay_%06d.png' "$out" "$pick")" "$here/docs/fig19_validation.png"
{
  echo
  echo "Frame $pick, bottom front (region $zoom, twice enlarged). Thick green: the selected candidate,"
  echo "kept by the pose; thick red: selected but rejected by the pose as an outlier; thin yellow: the"
  echo "other candidates; cyan circles: junctions found by validation; thin lines: the model at the"
  echo "estimated pose."
  echo
  echo "| EPIC alone (best candidate per edge) | EPIC + validation |"
  echo "|---|---|"
  echo "| ![epic](fig18_epic.png) | ![validation](fig19_validation.png) |"
} >> "$lines_section"

if ((sweep)); then
  "$here/tools/jerk_sweep.sh" --out "$out/jerk_sweep"
fi

{
  echo "# Tracking results"
  echo
  echo "Regenerated by \`tools/results.sh\` ($(date -u +%Y-%m-%d), $(nproc) cores, Release build;"
  echo "frames per scenario: ${frames:-as the scenario file says}). Do not edit by hand."
  echo
  if ((heldout)); then
    cat "$heldout_dir/section.md"
    echo
    echo "## The scenarios' own seeds"
    echo
    echo "Each scenario file's seed (the scene as designed, variety 0): one draw each, kept for"
    echo "comparison with earlier results and with ViSP; the held-out table above is what decides."
    echo
  fi
  echo "Simulated scenarios: success = within 5 cm and 5 deg of ground truth (a frame the tracker"
  echo "reports lost counts as failed); errors are medians over frames with an estimate. Real video"
  echo "(teabox, teabox_left; no ground truth): success and errors are against the peer's ViSP poses"
  echo "(reference_visp.csv), and the last column but one gives the RMS distance of the projected model"
  echo "corners to the hand-read corners (about +-2-3 px) of the first / last frame."
  echo "ms = the tracking step alone per frame (median), without decoding and drawing."
  echo "Over $seeds seeds: the success rate of the same run with the default RANSAC seed and seeds"
  echo "1..$((seeds - 1)) (\`track --ransac-seed\`), median (min-max); the other columns are the default seed's."
  echo "Where the spread is wide, one run is one draw: a marginal frame decides the rest of the sequence."
  echo
  echo "| sequence | tracker | IMU | success | rot. err. (deg) | transl. err. (mm) | success over $seeds seeds | losses / corners | ms |"
  echo "|---|---|---|---|---|---|---|---|---|"
  cat "$rows"
  if [[ ! -x "$visp" ]]; then
    echo
    echo "ViSP rows are missing: install libvisp-dev and rerun (tools/visp_compare builds only with it)."
  fi
  echo
  cat "$lines_section"
  if ((sweep)); then
    echo
    cat "$out/jerk_sweep/section.md"
  fi
} > "$here/docs/results.md"
echo "results: wrote docs/results.md (tracker outputs under $out)"

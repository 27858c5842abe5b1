#!/usr/bin/env bash
# Acquisition and re-acquisition (issue 23), measured from when the object can be seen: the
# acquisition scenarios (late_entry: it enters the view late; box_cover: a board hides it for
# a second; stumble: a 50 degree jolt throws it out of view and back) simulated on their own
# seed and on held-out seeds (each a new scene), tracked without init.csv and from init.csv,
# scored per frame up to the model's symmetries. The simulator's sim_truth.json gives the runs
# of frames in which the whole object is in view (`object_in_view_frames`); for the first run
# and for each run after the object was out of view, the number of frames from its first frame
# to the first frame tracked within 5 cm / 5 degrees. Writes DIR/rows.tsv and DIR/section.md
# (the table in docs/detection.md). Rows already in DIR/rows are kept: an interrupted run resumes.
# Usage: tools/acquisition_eval.sh [--seeds "own 101 ... 110"] [--scenarios "a b"] [--imu on|off]
#                                  [--jobs J] [--out DIR] [--bin PATH] [--table-only]
#   --seeds   "own" is the scenario file's seed; the numbers draw new scenes (default: own 101-110)
# Needs jq.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/bin/epichead"
seeds="own 101 102 103 104 105 106 107 108 109 110"
scenarios="late_entry box_cover stumble"
imu=off
jobs=$(nproc)
out="$here/out/acquisition_eval"
table_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --scenarios) scenarios="$2"; shift 2 ;;
    --imu) imu="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --table-only) table_only=1; shift ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "acquisition_eval: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
command -v jq > /dev/null || { echo "acquisition_eval: needs jq" >&2; exit 1; }
[[ -x "$bin" ]] || { echo "acquisition_eval: no program at $bin (./dev build first, or --bin)" >&2; exit 1; }
mkdir -p "$out/rows"
export EPICHEAD_CACHE_DIR="$out/template_cache"

# frames_to_track PER_FRAME.csv FIRST LAST: frames from FIRST to the first frame in [FIRST, LAST]
# tracked within 5 cm / 5 degrees ("-" when none is).
frames_to_track() {
  awk -F, -v a="$2" -v b="$3" 'NR > 1 && $1 >= a && $1 <= b && $3 == 1 { print $1 - a; found = 1; exit }
                               END { if (!found) print "-" }' "$1"
}

# One scenario and seed. Row: scenario seed start_delay reentry_delays(comma list or "")
#   success_no_init success_init losses reacquisitions
one() {
  local scenario="$1" seed="$2"
  local row="$out/rows/$scenario-$seed.tsv"
  [[ -s "$row" ]] && return 0
  local seq="$out/seq/$scenario-$seed" work="$out/run/$scenario-$seed"
  rm -rf "$seq" "$work"
  mkdir -p "$work"
  local seed_arg=()
  [[ "$seed" != own ]] && seed_arg=(--seed "$seed")
  "$bin" sim "$scenario" --out "$seq" "${seed_arg[@]}" > /dev/null
  "$bin" track "$seq" --out "$work/init" --imu "$imu" --every 0 --no-video > "$work/init.log" 2>&1
  mkdir -p "$work/noinit-seq"
  cp -r "$seq"/. "$work/noinit-seq/"
  rm "$work/noinit-seq/init.csv"
  "$bin" track "$work/noinit-seq" --out "$work/noinit" --imu "$imu" --every 0 --no-video > "$work/noinit.log" 2>&1
  local s_no s_init
  s_no=$("$bin" score "$seq" "$work/noinit/poses.csv" --symmetric --per-frame "$work/noinit.csv" --json | jq -r '.success_rate * 100')
  s_init=$("$bin" score "$seq" "$work/init/poses.csv" --symmetric --json | jq -r '.success_rate * 100')
  if [[ -z "$s_no" || -z "$s_init" || ! -f "$work/noinit/report.json" ]]; then
    echo "acquisition_eval: $scenario seed $seed did not finish (see $work); no row" >&2
    return 0
  fi
  local runs start="-" reentries=()
  runs=$(jq -r '.object_in_view_frames[] | "\(.[0]) \(.[1])"' "$seq/sim_truth.json")
  local k=0
  while read -r first last; do
    [[ -z "$first" ]] && continue
    local d
    d=$(frames_to_track "$work/noinit.csv" "$first" "$last")
    if ((k == 0)); then start="$first:$d"; else reentries+=("$first:$d"); fi
    k=$((k + 1))
  done <<< "$runs"
  local IFS=,
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$scenario" "$seed" "$start" "${reentries[*]}" "$s_no" "$s_init" \
    "$(jq -r '.acquisition.losses' "$work/noinit/report.json")" "$(jq -r '.acquisition.reacquisitions' "$work/noinit/report.json")" > "$row"
  rm -rf "$seq" "$work/noinit-seq"
}
export -f one frames_to_track
export bin out imu

if ((!table_only)); then
  for scenario in $scenarios; do
    # The first run alone builds the template cache (one model and camera for all three).
    one "$scenario" "${seeds%% *}"
    for seed in ${seeds#* }; do echo "$scenario $seed"; done | xargs -r -P "$jobs" -L 1 bash -c 'one "$0" "$1"'
  done
fi
cat "$out"/rows/*.tsv | sort -k1,1 -k2,2 > "$out/rows.tsv"

# The table: per scenario, runs tracked within 10 frames of the object first being wholly in
# view, re-entries tracked again within 10 frames, the frames that took (median, max), and the
# success without and with init.csv.
awk -F'\t' '
  function med(a, n,   i, j, t) { for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                                  return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
  { k = $1; n[k]++
    split($3, st, ":"); if (st[2] != "-" && st[2] <= 10) start_ok[k]++
    if (st[2] != "-") { ns[k]++; sd[k, ns[k]] = st[2] }
    m = split($4, re, ",")
    for (i = 1; i <= m; i++) { split(re[i], e, ":"); reent[k]++
      if (e[2] != "-") { nr[k]++; rd[k, nr[k]] = e[2]; if (e[2] <= 10) re_ok[k]++ } }
    no[k, n[k]] = $5; init[k, n[k]] = $6; within[k] += ($5 >= $6 - 2) }
  END {
    print "| scenario | runs | tracked within 10 frames of first in view | frames (median / max) | re-entries tracked within 10 frames | frames (median / max) | success without init.csv (median) | with init.csv (median) | runs without init.csv >= with - 2 points |"
    print "|---|---|---|---|---|---|---|---|---|"
    for (k in n) {
      for (i = 1; i <= n[k]; i++) { a[i] = no[k, i]; b[i] = init[k, i] }
      smed = "-"; smax = "-"; if (ns[k]) { mx = 0; for (i = 1; i <= ns[k]; i++) { c[i] = sd[k, i]; if (c[i] > mx) mx = c[i] }; smed = med(c, ns[k]); smax = mx }
      rmed = "-"; rmax = "-"; if (nr[k]) { mx = 0; for (i = 1; i <= nr[k]; i++) { c[i] = rd[k, i]; if (c[i] > mx) mx = c[i] }; rmed = med(c, nr[k]); rmax = mx }
      printf "| %s | %d | %d / %d | %s / %s | %d / %d | %s / %s | %.1f %% | %.1f %% | %d / %d |\n", k, n[k], start_ok[k], n[k], smed, smax,
             re_ok[k], reent[k], rmed, rmax, med(a, n[k]), med(b, n[k]), within[k], n[k]
    }
  }' "$out/rows.tsv" | { read -r h; read -r s; echo "$h"; echo "$s"; sort; } > "$out/section.md"
cat "$out/section.md"

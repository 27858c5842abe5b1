#!/usr/bin/env bash
# Detection without a starting pose (issue 23), on development and held-out seeds: every
# scenario simulated as a new scene per seed (`epichead sim --seed N`), the object detected in
# its first and middle frames (`epichead detect`), and the sequence tracked without init.csv
# (detection finds the start and re-acquires after losses) beside the same run from init.csv.
# Scored up to the model's symmetries (a box's half turns) and, for bodies of revolution, the
# turn about their axis. Writes DIR/rows.tsv and DIR/section.md (the table in docs/detection.md).
# Runs already in DIR/rows are kept, so an interrupted evaluation resumes where it stopped.
# Usage: tools/detection_eval.sh [--dev "1 2 3"] [--held "101 ... 112"] [--scenarios "a b"]
#                                [--frames N] [--jobs J] [--out DIR] [--bin PATH] [--detect-only]
#   --scenarios   default: mockup_walk box_clutter lampshade can bowl (office_pan's model is the
#                 room around the camera: it is never wholly in view, which detection needs)
#   --frames N    frames per sequence (default 90)
#   --detect-only detection in the first and middle frames alone, no tracking (the tracking
#                 columns then show "-")
#   --table-only  only make the table from the rows in DIR (of a run still going, or stopped)
# Needs jq.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/bin/epichead"
dev="1 2 3"
held="101 102 103 104 105 106 107 108 109 110 111 112"
scenarios="mockup_walk box_clutter lampshade can bowl"
frames=90
jobs=$(nproc)
out="$here/out/detection_eval"
table_only=0
detect_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --dev) dev="$2"; shift 2 ;;
    --held) held="$2"; shift 2 ;;
    --scenarios) scenarios="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --table-only) table_only=1; shift ;;
    --detect-only) detect_only=1; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "detection_eval: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
command -v jq > /dev/null || { echo "detection_eval: needs jq" >&2; exit 1; }
[[ -x "$bin" ]] || { echo "detection_eval: no program at $bin (./dev build first, or --bin)" >&2; exit 1; }
mkdir -p "$out/rows"
export EPICHEAD_CACHE_DIR="$out/template_cache"

# Score options for a scenario's model: its symmetries, and the axis of a body of revolution.
score_args() {
  case "$1" in lampshade|can|bowl) echo "--symmetric --sym-axis 0,0,1" ;; *) echo "--symmetric" ;; esac
}

# One scenario and seed. Row: scenario seed set found0 right0 found_mid right_mid detect_ms
#   success_no_init success_init reacquisitions losses start_frame
one() {
  local scenario="$1" seed="$2" set="$3"
  # A run already done is kept (an interrupted evaluation resumes; delete DIR/rows to redo it).
  [[ -s "$out/rows/$scenario-$seed.tsv" ]] && return 0
  local seq="$out/seq/$scenario-$seed" work="$out/run/$scenario-$seed"
  rm -rf "$seq" "$work"
  mkdir -p "$work"
  "$bin" sim "$scenario" --out "$seq" --seed "$seed" --frames "$frames" > /dev/null
  local sargs
  sargs=$(score_args "$scenario")
  local cols=()
  for f in 0 $((frames / 2)); do
    local d="$work/detect-$f" found=0 right=0 ms=nan
    if "$bin" detect "$seq" --frame "$f" --out "$d" > "$d.log" 2>&1; then found=1; fi
    if [[ -f "$d/pose.csv" ]]; then
      # One pose scored against the whole gt.csv: it succeeded when one frame did.
      right=$("$bin" score "$seq" "$d/pose.csv" --json $sargs | jq -r '.succeeded')
    fi
    [[ -f "$d/detection.json" ]] && ms=$(jq -r '.match_ms + .refine_ms' "$d/detection.json")
    cols+=("$found" "$right")
    [[ $f == 0 ]] && local ms0="$ms"
  done
  if ((detect_only)); then
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t-\t-\t-\t-\t-\n' "$scenario" "$seed" "$set" "${cols[@]}" "$ms0" > "$out/rows/$scenario-$seed.tsv"
    rm -rf "$seq"
    return 0
  fi
  "$bin" track "$seq" --out "$work/init" --every 0 --no-video > "$work/init.log" 2>&1
  local no_init="$out/seq/$scenario-$seed-noinit"
  rm -rf "$no_init"
  cp -r "$seq" "$no_init"
  rm "$no_init/init.csv"
  "$bin" track "$no_init" --out "$work/noinit" --every 0 --no-video > "$work/noinit.log" 2>&1
  local s_no s_init
  s_no=$("$bin" score "$seq" "$work/noinit/poses.csv" --json $sargs | jq -r '.success_rate * 100')
  s_init=$("$bin" score "$seq" "$work/init/poses.csv" --json $sargs | jq -r '.success_rate * 100')
  rm -rf "$no_init"
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$scenario" "$seed" "$set" "${cols[@]}" "$ms0" "$s_no" "$s_init" \
    "$(jq -r '.acquisition.reacquisitions' "$work/noinit/report.json")" "$(jq -r '.acquisition.losses' "$work/noinit/report.json")" \
    "$(jq -r '.acquisition.start.frame // "-"' "$work/noinit/report.json")" > "$out/rows/$scenario-$seed.tsv"
}
export -f one score_args
export bin out frames detect_only

runs() {  # scenario seed set, one per line
  for s in $dev; do echo "$1 $s dev"; done
  for s in $held; do echo "$1 $s held"; done
}
for scenario in $scenarios; do
  ((table_only)) && break
  echo "detection_eval: $scenario (templates are built once, then read from $EPICHEAD_CACHE_DIR)" >&2
  # The first run alone builds the template cache; the others read it, in parallel.
  runs "$scenario" | head -1 | xargs -L 1 bash -c 'one "$0" "$1" "$2"'
  runs "$scenario" | tail -n +2 | xargs -r -P "$jobs" -L 1 bash -c 'one "$0" "$1" "$2"'
done
cat "$out"/rows/*.tsv | sort -k1,1 -k2,2n > "$out/rows.tsv"

# The table: per scenario and seed set, detections right in the first and middle frames, the
# median and minimum success of tracking without init.csv, and runs within a point of the run from init.csv.
awk -F'\t' '
  function med(a, n,   i, j, t) { for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                                  return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
  NF < 13 || $9 == "" || $10 == "" { next }  # a run cut short (its row is incomplete)
  { k = $1 " " $3; n[k]++; right[k] += $5 + $7; found_wrong[k] += ($4 && !$5) + ($6 && !$7)
    ms[k, n[k]] = $8
    if ($9 == "-") next  # detection only
    t[k]++; no[k, t[k]] = $9; if (!(k in mn) || $9 < mn[k]) mn[k] = $9; ok[k] += ($9 >= $10 - 1)
    re[k] += $11 }
  END {
    print "| scenario | seeds | detected right (frames 0 and middle) | found but wrong | detect ms median | no init.csv: median / min success % | runs >= init.csv run - 1 | re-acquisitions |"
    print "|---|---|---|---|---|---|---|---|"
    for (k in n) {
      split(k, p, " "); m = n[k]
      for (i = 1; i <= m; i++) b[i] = ms[k, i]
      printf "| %s | %s (%d) | %d / %d | %d | %.0f | ", p[1], p[2], m, right[k], 2 * m, found_wrong[k], med(b, m)
      if (!t[k]) { print "- | - | - |"; continue }
      for (i = 1; i <= t[k]; i++) a[i] = no[k, i]
      printf "%.1f / %.1f | %d / %d | %d |\n", med(a, t[k]), mn[k], ok[k], t[k], re[k]
    }
  }' "$out/rows.tsv" | { read -r h; read -r s; echo "$h"; echo "$s"; sort; } > "$out/section.md"
cat "$out/section.md"

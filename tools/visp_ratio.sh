#!/usr/bin/env bash
# ViSP's edge tracker and epichead's tracking step timed in one run (issue 24's ratio): per
# sequence the two programs alternate RUNS times on the same frames, and the ratio of their
# median times per frame is taken pair by pair, so that a machine whose speed drifts moves both
# of a pair alike. Quote the median ratio, never single times from different runs.
#
# Usage: tools/visp_ratio.sh [--runs N] [--frames N] [--out DIR] [--bin DIR] [SEQ|SCENARIO ...]
#   SEQ       a sequence directory (camera.yaml, model.cao, frames, init.csv)
#   SCENARIO  a built-in scenario, simulated once into DIR (its default seed, --frames frames)
#   default   ../shared/data/teabox, ../shared/data/teabox_left and the six scenarios
#   --runs    pairs per sequence (default 3)    --frames  frames per simulated scenario (default 150)
#   --out     where runs are kept (default: a temporary directory)
#   --bin     the build's bin directory (default build/bin): epichead and epichead-visp
#
# What is timed (docs/visp_compare.md, docs/performance.md):
#   ViSP      its track() call alone, wall clock, one thread (epichead-visp's report.json
#             track_ms: frames decoded, undistorted and converted to grey before the clock);
#   epichead  its tracking step, wall clock, one thread (report.json track_ms: the window
#             image's tiles its windows read are converted inside it; the frame's copy at
#             assign, about 15 us, is not), --mode epic+validation --imu off --image-motion off.
# Both start from init.csv. Needs jq, and epichead-visp (built when libvisp-dev is installed).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
runs=3 frames=150 out="" bin="$here/build/bin"
sequences=()
while (($#)); do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "visp_ratio: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) sequences+=("$1"); shift ;;
  esac
done
command -v jq > /dev/null || { echo "visp_ratio: needs jq" >&2; exit 2; }
[[ -x "$bin/epichead" ]] || { echo "visp_ratio: no $bin/epichead (build first, or --bin)" >&2; exit 2; }
[[ -x "$bin/epichead-visp" ]] || { echo "visp_ratio: no $bin/epichead-visp (install libvisp-dev and build; docs/visp_compare.md)" >&2; exit 2; }
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "visp_ratio: --runs must be a positive integer, got '$runs'" >&2; exit 2; }
if [[ -z "$out" ]]; then out="$(mktemp -d)"; trap 'rm -rf "$out"' EXIT; fi
mkdir -p "$out"
if ((${#sequences[@]} == 0)); then
  sequences=("$here/../shared/data/teabox" "$here/../shared/data/teabox_left" bowl box_clutter can lampshade mockup_walk office_pan)
fi

median() { sort -g | awk '{v[NR] = $1} END {if (NR == 0) print "nan"; else print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2)}'; }

echo "| sequence | frames | ViSP track() ms | epichead step ms | ratio | epichead p99 ms | epichead worst ms (x median) | tracked ViSP / epichead |"
echo "|---|---|---|---|---|---|---|---|"
for s in "${sequences[@]}"; do
  if [[ -d "$s" ]]; then
    seq="$s" name="$(basename "$s")"
  else
    name="$s" seq="$out/$s/seq"
    if [[ ! -d "$seq" ]]; then
      echo "visp_ratio: simulating $s ($frames frames)" >&2
      "$bin/epichead" sim "$s" --out "$seq" --frames "$frames" > "$out/$s.sim.log" 2>&1 ||
        { echo "visp_ratio: epichead sim $s failed: $(tail -1 "$out/$s.sim.log")" >&2; exit 1; }
    fi
  fi
  [[ -f "$seq/init.csv" ]] || { echo "visp_ratio: $seq has no init.csv (both trackers start from it)" >&2; exit 1; }
  ratios="" v_ms="" e_ms="" e_p99="" e_max=""
  for ((r = 1; r <= runs; ++r)); do
    echo "visp_ratio: $name, pair $r of $runs" >&2
    v="$out/$name/visp-$r" e="$out/$name/epichead-$r"
    mkdir -p "$out/$name"
    "$bin/epichead-visp" "$seq" --out "$v" --mode edges > "$v.log" 2>&1 ||
      { echo "visp_ratio: epichead-visp on $seq failed: $(tail -1 "$v.log")" >&2; exit 1; }
    "$bin/epichead" track "$seq" --out "$e" --mode epic+validation --imu off --image-motion off --every 0 --no-video \
      > "$e.log" 2>&1 || { echo "visp_ratio: epichead track on $seq failed: $(tail -1 "$e.log")" >&2; exit 1; }
    vm=$(jq -r '.track_ms_median' "$v/report.json") em=$(jq -r '.track_ms_median' "$e/report.json")
    v_ms+="$vm"$'\n' e_ms+="$em"$'\n'
    ratios+="$(awk -v a="$vm" -v b="$em" 'BEGIN {print a / b}')"$'\n'
    e_p99+="$(jq -r '.track_ms_p99' "$e/report.json")"$'\n'
    e_max+="$(jq -r '[.per_frame[] | .ms.total // empty] | max' "$e/report.json")"$'\n'
  done
  vmed=$(median <<< "${v_ms%$'\n'}") emed=$(median <<< "${e_ms%$'\n'}")
  worst=$(median <<< "${e_max%$'\n'}")
  printf "| %s | %s | %.3f | %.3f | %.2f | %.3f | %.2f (%.1fx) | %s / %s |\n" "$name" \
    "$(jq -r '.frames' "$out/$name/epichead-1/report.json")" "$vmed" "$emed" "$(median <<< "${ratios%$'\n'}")" \
    "$(median <<< "${e_p99%$'\n'}")" "$worst" "$(awk -v a="$worst" -v b="$emed" 'BEGIN {print a / b}')" \
    "$(jq -r '.tracked' "$out/$name/visp-1/report.json")" "$(jq -r '.tracked' "$out/$name/epichead-1/report.json")"
done

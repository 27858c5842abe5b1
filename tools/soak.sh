#!/usr/bin/env bash
# The soak run (issue 22, item 5): `epichead sim-run --soak` for a long simulated time on
# mockup_walk walking in place (steps and their bursts go on, the body does not walk away from
# the mockup), in fixate mode, with a fault injected every PERIOD seconds in turn: IMU dropout,
# bus-off, camera stall, stuck tilt joint, stuck pan joint. Then it checks, from summary.json and
# the diagnostics stream:
#   - memory: resident memory at the end at most --memory-slack-kib (1024) above what it was
#     after warm-up;
#   - faults: every fault the controller raised was cleared, and the loop ends in the mode asked;
#   - attitude: the predictor's attitude error late in the run at most 2x (+ 0.05 deg) its error
#     early in the run (vision keeps correcting it: no drift).
# Prints a table of faults raised and cleared, and exits 1 when a check fails.
#
#   tools/soak.sh [--seconds S] [--period S] [--warmup S] [--seed N] [--downscale 1|2|4] [--out DIR] [--bin BIN]
#                 [--memory-slack-kib N] [--markdown FILE]
#
# Defaults: 3600 s, a fault every 180 s, 60 s of warm-up before the memory baseline, seed 1,
# camera downscaled 2x, Release build. --markdown writes the figures as a markdown section
# (docs/head.md takes it). ctest runs a short one.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds=3600
period=180
warmup=60
seed=1
downscale=2
slack_kib=1024
out="$here/out/soak"
bin=""
markdown=""
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --period) period="$2"; shift 2 ;;
    --warmup) warmup="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --downscale) downscale="$2"; shift 2 ;;
    --memory-slack-kib) slack_kib="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --markdown) markdown="$2"; shift 2 ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "soak: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v jq >/dev/null || { echo "soak: jq is missing (apt-get install jq)" >&2; exit 1; }
if [[ -z "$bin" ]]; then
  "$here/dev" build >/dev/null
  bin="$here/build/bin/epichead"
fi
mkdir -p "$out"

# mockup_walk in place, as many frames as the run needs, and the faults.
scn="$out/soak.scn"
frames=$(awk -v s="$seconds" 'BEGIN { printf "%d", s * 30 + 30 }')
sed -e '/^frames[[:space:]]/d' -e '/^speed_mps[[:space:]]/d' -e '/^fault[[:space:]]/d' \
  "$here/sim/scenarios/mockup_walk.scn" > "$scn"
{
  echo "frames $frames"
  echo "speed_mps 0"
  awk -v s="$seconds" -v p="$period" 'BEGIN {
    split("imu_dropout 0.5|bus_off 0.3|camera_stall 0.5|stuck_joint tilt 1.0|stuck_joint pan 1.0", kinds, "|")
    k = 0
    for (t = p; t + 5 < s; t += p) {
      n = split(kinds[k % 5 + 1], f, " ")
      if (n == 2) printf "fault %s %.1f %s\n", f[1], t, f[2]
      else printf "fault %s %s %.1f %s\n", f[1], f[2], t, f[3]
      k++
    }
  }'
} >> "$scn"
injected=$(grep -c '^fault ' "$scn" || true)

dir="$out/run"
rm -rf "$dir"
echo "soak: $seconds s simulated, $injected faults (one every $period s), seed $seed: $bin sim-run --soak"
start=$(date +%s)
"$bin" sim-run "$scn" --out "$dir" --mode fixate --seconds "$seconds" --seed "$seed" --every 0 --downscale "$downscale" --soak --soak-warmup-s "$warmup" \
  | tee "$out/sim_run.txt"
wall=$(( $(date +%s) - start ))

s="$dir/summary.json"
d="$dir/diagnostics.jsonl"
fail=0
bad() { echo "soak: FAILED: $*"; fail=1; }

warm=$(jq -r '.soak.rss_kib_after_warmup' "$s")
end=$(jq -r '.soak.rss_kib_end' "$s")
max=$(jq -r '.soak.rss_kib_max' "$s")
growth=$(awk -v a="$warm" -v b="$end" 'BEGIN { printf "%.0f", b - a }')
awk -v g="$growth" -v m="$slack_kib" 'BEGIN { exit !(g > m) }' && bad "memory grew by $growth KiB after warm-up (> $slack_kib)"

early=$(jq -r '.soak.predicted_attitude_error_deg_median_early' "$s")
late=$(jq -r '.soak.predicted_attitude_error_deg_median_late' "$s")
awk -v e="$early" -v l="$late" 'BEGIN { exit !(l > 2 * e + 0.05) }' && bad "the predicted attitude error grew from $early to $late deg"

# Faults raised and cleared, per fault; the mode at the end.
faults=$(jq -r 'select(.event == "fault_raised" or .event == "fault_cleared") | "\(.fault) \(.event)"' "$d" \
  | sort | uniq -c | awk '{ n[$2, $3] = $1; f[$2] = 1 }
      END { for (k in f) printf "%s %d %d\n", k, n[k, "fault_raised"], n[k, "fault_cleared"] }' | sort)
while read -r name raised cleared; do
  [[ -z "$name" ]] && continue
  ((raised == cleared)) || bad "$name raised $raised times, cleared $cleared times"
done <<<"$faults"
last_mode=$(jq -r 'select(.mode != null) | .mode' "$d" | tail -1)
[[ "$last_mode" == "fixate" ]] || bad "the loop ended in mode '$last_mode', not fixate"

table="| controller fault | raised | cleared |
|---|---|---|
$(awk '{ printf "| %s | %s | %s |\n", $1, $2, $3 }' <<<"$faults")"
echo "$table"
echo "soak: memory $warm KiB after warm-up, $end KiB at the end (growth $growth KiB, max $max KiB); predicted attitude error $early deg early, $late deg late; ended in $last_mode; $wall s of wall time"
if [[ -n "$markdown" ]]; then
  {
    echo "Generated by \`tools/soak.sh --seconds $seconds --period $period --seed $seed\` ($(git -C "$here" rev-parse --short HEAD), Release):"
    echo
    echo "- $seconds s simulated in $wall s; $injected faults injected (IMU dropout, bus-off, camera stall, stuck tilt, stuck pan in turn)."
    echo "- Resident memory: $warm KiB after the $(jq -r '.soak.warmup_s' "$s") s warm-up, $end KiB at the end (growth $growth KiB), $max KiB at most."
    echo "- Predicted attitude error at each frame's exposure (median): $early deg in the first $(jq -r '.soak.attitude_window_s | floor' "$s") s after warm-up, $late deg in the last."
    echo "- Tracking: $(jq -r '.loop.tracked' "$s") frames tracked, $(jq -r '.loop.lost' "$s") lost; the loop ended in $last_mode."
    echo
    echo "$table"
  } > "$markdown"
fi
exit $fail

# The onboard loop in the VM (run by init.sh, busybox sh): `epichead sim-peers` plays the IMU
# and the pan/tilt head on vcan1 in real time, `epichead run` runs the onboard loop on the vivid
# camera and that bus for RUN_S seconds, then `epichead replay` must read the candump log the
# loop recorded without a malformed line, unknown frame, error frame or decode error, with the
# IMU, head state and heartbeats in it. vivid shows test patterns, not the model, so the tracker
# is lost: the loop, the bus traffic, the log and the replay are what is tested.
run_s=${ONBOARD_RUN_S:-5}
rc=0
bad() { echo "onboard: FAILED: $*"; rc=1; }
cd /tmp || exit 1

# On the robot the IMU and the head are microcontrollers of their own. Here they run on CPU 0
# beside vision, which takes all of its CPU, at nice -15 so the scheduler gives them what they
# ask for first (vision keeps the rest). CPU 1 is the control thread's (SCHED_FIFO 80, woken
# every millisecond): under qemu's emulation it left the peers seconds behind there.
taskset 1 epichead sim-peers --can vcan1 --scenario /etc/onboard/peers.scn --seconds $((run_s + 120)) >/tmp/peers.log 2>&1 &
peers=$!
renice -n -15 -p $peers >/dev/null || bad "cannot raise the peers' priority"
# The nodes are on the bus before the loop starts (a sanitizer build under emulation takes seconds to start).
waited=0
until grep -q ': running' /tmp/peers.log 2>/dev/null; do
  [ $waited -lt 600 ] || { bad "sim-peers did not start within 60 s"; break; }
  sleep 0.1; waited=$((waited + 1))
done
epichead run --config /etc/onboard/run.json --seconds "$run_s" >/tmp/run.log 2>&1 || bad "epichead run exited $?"
cat /tmp/run.log
kill -TERM $peers   # the peers outlast the loop, however long its start took; they stop on the signal
wait $peers || bad "epichead sim-peers exited non-zero"
cat /tmp/peers.log

# "run: T ticks (L late), F frames (K tracked, X lost), I IMU samples, C commands"
summary=$(grep '^run: [0-9]* ticks' /tmp/run.log)
field() { echo "$summary" | sed -n "s/.* \([0-9][0-9]*\) $1.*/\1/p"; }
frames=$(field 'frames'); imu=$(field 'IMU samples'); commands=$(field 'commands')
[ -n "$frames" ] && [ "$frames" -gt 0 ] || bad "no camera frames reached the loop ($summary)"
[ -n "$imu" ] && [ "$imu" -gt 0 ] || bad "no IMU samples reached the loop ($summary)"
[ -n "$commands" ] && [ "$commands" -gt 0 ] || bad "the loop sent no head commands ($summary)"

# The deadlines, measured on the control thread (issue 22): printed, and the missed ticks checked.
summary_json=/tmp/run-out/summary.json
if [ -s "$summary_json" ]; then
  jq -c '{ticks, late_ticks, frames, deadlines}' "$summary_json"
  jq -c '{bus_errors, unknown_frames, undecodable_frames, imu_rejected, imu_clock_sync, imu_assembly, predictor}' "$summary_json"
  # Under KVM the vCPUs are real CPU time and the bound is the loop's; under TCG (software
  # emulation, a shared host) the emulator itself stalls the vCPUs for milliseconds, so the
  # figures are printed but not held to the bound.
  accel=$(sed -n 's/.*epichead_accel=\([a-z]*\).*/\1/p' /proc/cmdline)
  if [ "$accel" != kvm ]; then
    echo "onboard: note control ticks missed: $(jq -c '.deadlines | {ticks_missed, ticks_missed_fraction}' "$summary_json") (not checked under $accel: emulated CPU)"
  elif jq -e '.frames > 0 and .deadlines.ticks_missed_fraction <= 0.001' "$summary_json" >/dev/null; then
    echo "onboard: ok   control ticks missed <= 0.1 % while vision ran"
  else
    bad "control ticks missed > 0.1 % (or no frame tracked): $(jq -c '.deadlines | {ticks_missed, ticks_missed_fraction}' "$summary_json")"
  fi
else
  bad "no $summary_json"
fi

log=/tmp/run-out/bus.log
[ -s "$log" ] || { bad "no candump log at $log"; exit 1; }
echo "onboard: $(wc -l <"$log") lines in $log, first: $(head -1 "$log")"
if ! epichead replay "$log" --json >/tmp/replay.json 2>/tmp/replay.err; then
  cat /tmp/replay.err
  bad "epichead replay failed"
  exit 1
fi
# One jq expression per property, each printed with its verdict.
check() {
  if jq -e "$1" /tmp/replay.json >/dev/null; then echo "onboard: ok   $1"; else bad "replay: $1"; fi
}
check '.malformed_lines == 0'
check '.timestamps == "all"'
check '.duration_s > 0 and .duration_s < 60'   # one time base: sent and received frames on the same clock
check '.start_s > 1.6e9'                        # on the wall clock, as candump stamps (after 2020)
check '.error_frames == 0'
check '.unknown_frames == 0'
check '[.ids[] | .stamps_backwards // 0] | add == 0'
check '[.messages[] | .decode_errors[]] | add // 0 | . == 0'
check '.imu_samples > 0'
check '.messages.HeadState.decoded > 0'
check '.messages.HeadCommand.decoded > 0'
check '.messages.TimeSyncReply.decoded > 0'
check '.messages.Heartbeat.decoded > 0'
jq -c '[.ids[] | select(.stamps_backwards) | {id, message, stamps_backwards}]' /tmp/replay.json
jq -c '{frames, duration_s, bus_load, imu_samples, messages: (.messages | map_values({decoded, counter_lost}))}' /tmp/replay.json
exit $rc

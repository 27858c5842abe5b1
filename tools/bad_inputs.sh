#!/usr/bin/env bash
# Runs bad inputs through `epichead` and records what each gives: the table of docs/reliability.md
# under "## Bad inputs" (input, command, the first line of the message, exit code).
#
#   tools/bad_inputs.sh [BIN]           rewrite the table in docs/reliability.md
#   tools/bad_inputs.sh --check [BIN]   compare with the committed table; fail if they differ
#
# BIN is the built program (default: build/bin/epichead). Each input is made in a scratch
# directory from the teabox sequence (../shared/data) and the tests' fixtures. The script fails
# when an input crashes the program, hangs it (60 s), or gives another exit code than the one
# listed (1: a runtime error with one line, 2: a command line that does not parse, 0: accepted,
# with the problem counted in the report).
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
check=0
bin=""
for arg in "$@"; do
  case "$arg" in
    --check) check=1 ;;
    -h | --help) sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) bin="$arg" ;;
  esac
done
bin="${bin:-$here/build/bin/epichead}"
if [[ ! -x "$bin" ]]; then
  echo "bad_inputs: no program at $bin (build it, or give its path)" >&2
  exit 2
fi
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"
teabox="$here/../shared/data/teabox"
fixtures="$here/tests/data"
doc="$here/docs/reliability.md"
if ((check)) && ! grep -q '^## Bad inputs' "$doc" 2> /dev/null; then
  echo "bad_inputs: $doc has no '## Bad inputs' table yet: generate it with tools/bad_inputs.sh [BIN]" >&2
  exit 77  # ctest: skipped (SKIP_RETURN_CODE), not passed
fi
for f in "$teabox/video.mp4" "$fixtures/seq/cube.cao"; do
  [[ -f "$f" ]] || { echo "bad_inputs: missing $f" >&2; exit 2; }
done

W="$(mktemp -d "${TMPDIR:-/tmp}/epichead_bad_inputs.XXXXXX")"
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 2

# ---------------------------------------------------------------- inputs

# seq NAME: a copy of the teabox sequence (camera.yaml, model.cao, init.csv, video.mp4) in W/NAME.
seq() {
  mkdir -p "$1"
  for f in camera.yaml model.cao init.csv video.mp4; do cp "$teabox/$f" "$1/$f"; done
  chmod u+w "$1"/*
}
# put FILE TEXT: FILE holds exactly TEXT (printf escapes allowed).
put() { rm -f "$1"; printf "$2" > "$1"; }
# tiny_frames NAME: a sequence of three 640x480 PNG frames listed in frames.csv (from the video).
good_imu='t_s,gx,gy,gz,ax,ay,az\n0.00,0,0,0,0,0,9.81\n0.01,0,0,0,0,0,9.81\n0.02,0,0,0,0,0,9.81\n'

camera_yaml() {  # camera_yaml WIDTH HEIGHT [EXTRA]: the teabox camera with another size or extra keys
  printf '%%YAML:1.0\n---\nimage_width: %s\nimage_height: %s\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 839.2, 0., 325.0, 0., 839.2, 243.7, 0., 0., 1. ]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: %s\n   dt: d\n   data: [ %s ]\n%s' \
    "$1" "$2" "${4:-5}" "${5:-0., 0., 0., 0., 0.}" "${3:-}"
}

make_inputs() {
  # models
  seq model_missing && rm model_missing/model.cao
  seq model_empty && put model_empty/model.cao ''
  seq model_binary && head -c 300 "$teabox/video.mp4" > model_binary/model.cao.tmp && mv model_binary/model.cao.tmp model_binary/model.cao
  seq model_truncated && head -n 6 "$teabox/model.cao" > model_truncated/t && mv model_truncated/t model_truncated/model.cao
  seq model_index && put model_index/model.cao 'V1\n3\n0 0 0\n0.1 0 0\n0 0.1 0\n0\n0\n1\n3 0 1 7\n0\n0\n'
  seq model_huge && put model_huge/model.cao 'V1\n3\n0 0 0\n1e308 0 0\n0 0.1 0\n0\n0\n1\n3 0 1 2\n0\n0\n'
  seq model_nan && put model_nan/model.cao 'V1\n3\n0 0 0\nnan 0 0\n0 0.1 0\n0\n0\n1\n3 0 1 2\n0\n0\n'
  seq model_cycle && put model_cycle/model.cao 'V1\nload("model.cao")\n0\n0\n0\n0\n0\n0\n'
  seq model_far && cp "$teabox/model.cao" model_far/part.cao &&
    put model_far/model.cao 'V1\nload("part.cao", t=[0;0;1e308])\n0\n0\n0\n0\n0\n0\n'
  # camera calibrations
  seq cam_missing && rm cam_missing/camera.yaml
  seq cam_empty && put cam_empty/camera.yaml ''
  seq cam_binary && head -c 300 "$teabox/video.mp4" > cam_binary/c && mv cam_binary/c cam_binary/camera.yaml
  seq cam_typo && sed 's/rows: 3/rows:`3/' "$teabox/camera.yaml" > cam_typo/c && mv cam_typo/c cam_typo/camera.yaml
  seq cam_emptykey && camera_yaml '{ :3 }' 480 > cam_emptykey/camera.yaml
  seq cam_fisheye && camera_yaml 640 480 $'fisheye_model: 1\n' 5 '0.1, 0.01, 0., 0., 0.' > cam_fisheye/camera.yaml
  seq cam_ros && camera_yaml 640 480 $'distortion_model: rational_polynomial\n' > cam_ros/camera.yaml
  seq cam_ros_model && camera_yaml 640 480 $'distortion_model: fov\n' > cam_ros_model/camera.yaml
  seq cam_nine && camera_yaml 640 480 '' 9 '0., 0., 0., 0., 0., 0., 0., 0., 0.' > cam_nine/camera.yaml
  seq cam_small && camera_yaml 320 240 > cam_small/camera.yaml
  seq cam_focal && camera_yaml 640 480 | sed 's/839.2, 0., 325.0/-839.2, 0., 325.0/' > cam_focal/c && mv cam_focal/c cam_focal/camera.yaml
  seq cam_big && { camera_yaml 640 480; head -c 1100000 /dev/zero | tr '\0' '#'; } > cam_big/camera.yaml
  # images and video
  seq video_garbage && head -c 5000 /dev/zero | tr '\0' 'x' > video_garbage/video.mp4
  seq video_empty && put video_empty/video.mp4 ''
  seq frames_missing && rm frames_missing/video.mp4 &&
    put frames_missing/frames.csv 'frame,t_s,file\n0,0.0,frames/000000.png\n1,0.04,frames/000001.png\n'
  seq frames_corrupt && rm frames_corrupt/video.mp4 && mkdir frames_corrupt/frames &&
    put frames_corrupt/frames/000000.png '\211PNG\r\n\032\n not really a PNG' &&
    put frames_corrupt/frames.csv 'frame,t_s,file\n0,0.0,frames/000000.png\n'
  # poses, ground truth, IMU
  seq init_missing && rm init_missing/init.csv
  seq init_nan && put init_nan/init.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,nan,0,0.5,1,0,0,0\n'
  seq init_quat && put init_quat/init.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,0.5,0,0,0,0\n'
  seq init_header && put init_header/init.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n'
  seq init_columns && put init_columns/init.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,0.5,1,0\n'
  seq gt_columns && put gt_columns/gt.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0\n'
  seq gt_order && put gt_order/gt.csv 'frame,t_s,tx,ty,tz,qw,qx,qy,qz\n1,0.04,0,0,0.5,1,0,0,0\n0,0,0,0,0.5,1,0,0,0\n'
  seq imu_nan && put imu_nan/imu.csv 't_s,gx,gy,gz,ax,ay,az\n0.00,0,0,0,0,0,9.81\n0.01,nan,0,0,0,0,9.81\n'
  seq imu_saturated && put imu_saturated/imu.csv 't_s,gx,gy,gz,ax,ay,az\n0.00,1e30,0,0,0,0,9.81\n0.01,1e30,0,0,0,0,9.81\n'
  seq imu_order && put imu_order/imu.csv 't_s,gx,gy,gz,ax,ay,az\n0.02,0,0,0,0,0,9.81\n0.01,0,0,0,0,0,9.81\n'
  seq imu_text && put imu_text/imu.csv 't_s,gx,gy,gz,ax,ay,az\n0.00,0,0,0,0,0,g\n'
  put poses_garbage.csv 'this is not,a poses file\n\001\002\n'
  # CAN logs
  put can_empty.log ''
  printf '(1436509052.249713) can0 123#DEADBEEF\n(1436509052.249913) can0 1F334455#00\n(1436509052.2501' > can_truncated.log
  head -c 3000 "$teabox/video.mp4" > can_garbled.log
  printf '(1.000000) can0 123#00\n  can0  123  [12]  remote request\n(1.000100) can0 123#R8_\n' > can_impossible.log
  { printf '(1.000000) can0 123#'; head -c 10000 /dev/zero | tr '\0' 'A'; printf '\n(1.000100) can0 124#00\n'; } > can_long.log
  # DBC files (replay --dbc)
  put dbc_ok.dbc 'BO_ 256 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|0] "" N\n'
  put dbc_truncated.dbc 'BO_ 256 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|'
  put dbc_order.dbc 'BO_ 256 M: 8 N\n SG_ a : 0|8@2+ (1,0) [0|0] "" N\n'
  put dbc_beyond.dbc 'BO_ 256 M: 8 N\n SG_ a : 60|8@1+ (1,0) [0|0] "" N\n'
  put dbc_beyond_fd.dbc 'BO_ 256 M: 64 N\n SG_ a : 508|8@1+ (1,0) [0|0] "" N\n'
  put dbc_unclosed.dbc 'BO_ 256 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|0] "" N\nCM_ SG_ 256 a "no end;\n'
  put dbc_nomux.dbc 'BO_ 256 M: 8 N\n SG_ a m1 : 0|8@1+ (1,0) [0|0] "" N\n'
  head -c 3000 "$teabox/video.mp4" > dbc_garbled.dbc
  # scenarios and run configurations
  put scn_garbage.scn 'this is not a scenario\n\377\376\n'
  put scn_nan.scn 'scene can\nframes nan\nfps 30\n'
  put scn_unknown_key.scn 'scene can\nframes 3\nwings 2\n'
  put run_notjson.json '{ "model": '
  put run_nokey.json '{ "camera_calibration": "c.yaml", "init_pose": "i.csv" }'
  put run_type.json '{ "model": 3, "camera_calibration": "c.yaml", "init_pose": "i.csv" }'
  put run_unknown.json '{ "model": "m.cao", "camera_calibration": "c.yaml", "camera": { "widht": 1280 } }'
  put run_mode.json "{ \"model\": \"$teabox/model.cao\", \"camera_calibration\": \"$teabox/camera.yaml\", \"init_pose\": \"$teabox/init.csv\", \"mode\": \"dance\" }"
}

# ---------------------------------------------------------------- the runs

rows=()
problems=()
# run EXPECTED_EXIT "input" ARGS...: runs `epichead ARGS` in W and adds a table row.
run() {
  local expected="$1" input="$2"
  shift 2
  local shown="epichead $*"
  timeout 60 "$bin" "$@" > "$W/.out" 2> "$W/.err" < /dev/null
  local code=$?
  local message
  # The program's own line, not a library's (FFmpeg and libpng write theirs first, FFmpeg's
  # with a pointer that differs from run to run).
  message="$(grep -m1 '^epichead' "$W/.err")"
  [[ -z "$message" ]] && message="$(grep -m1 -v '^[[:space:]]*$' "$W/.err")"
  [[ -z "$message" ]] && message="$(grep -m1 -v '^[[:space:]]*$' "$W/.out")"
  # Paths in the scratch and data folders are shown relative to them; bytes that are not
  # printable (there should be none: printable.h) as '?'.
  message="${message//$W\//}"
  message="${message//$W/.}"
  message="${message//$teabox/teabox}"
  message="$(printf '%s' "$message" | LC_ALL=C tr -c '[:print:]' '?' | sed 's/|/\\|/g')"
  shown="${shown//$teabox/teabox}"
  local result="$code"
  if ((code == 124)); then
    result="hang (killed after 60 s)"
  elif ((code >= 128)); then
    result="crash (signal $((code - 128)))"
  fi
  if [[ "$code" != "$expected" ]]; then
    problems+=("$input: exit $result, expected $expected: $message")
  fi
  rows+=("| $input | \`${shown//|/\\|}\` | ${message} | $result |")
}

make_inputs 2> "$W/.make_errors" || true
if [[ -s "$W/.make_errors" ]]; then
  echo "bad_inputs: making the inputs failed:" >&2
  cat "$W/.make_errors" >&2
  exit 2
fi

T="track"
O="--out out --no-video --every 0 --frames 2"
# shellcheck disable=SC2086
{
  run 1 "model.cao missing" $T model_missing $O
  run 1 "model.cao empty" $T model_empty $O
  run 1 "model.cao binary (video bytes)" $T model_binary $O
  run 1 "model.cao truncated after 6 lines" $T model_truncated $O
  run 1 "model.cao face with a point index out of range" $T model_index $O
  run 1 "model.cao point at 1e308 m" $T model_huge $O
  run 1 "model.cao NaN coordinate" $T model_nan $O
  run 1 "model.cao that load()s itself" $T model_cycle $O
  run 1 "model.cao load() with t=[0;0;1e308]" $T model_far $O
  run 1 "camera.yaml missing" $T cam_missing $O
  run 1 "camera.yaml empty" $T cam_empty $O
  run 1 "camera.yaml binary (video bytes)" $T cam_binary $O
  run 1 "camera.yaml typo in rows (OpenCV would ask for 48 GB)" $T cam_typo $O
  run 1 "camera.yaml empty key (OpenCV throws std::length_error)" $T cam_emptykey $O
  run 1 "camera.yaml fisheye_model: 1 with 5 coefficients" $T cam_fisheye $O
  run 1 "camera.yaml ROS distortion_model: rational_polynomial with 5 coefficients" $T cam_ros $O
  run 1 "camera.yaml ROS distortion_model: fov (not supported)" $T cam_ros_model $O
  run 1 "camera.yaml 9 distortion coefficients (not an OpenCV model)" $T cam_nine $O
  run 1 "camera.yaml 320x240 for 640x480 video" $T cam_small $O
  run 1 "camera.yaml negative focal length" $T cam_focal $O
  run 1 "camera.yaml larger than 1 MiB" $T cam_big $O
  run 1 "video.mp4 garbage" $T video_garbage $O
  run 1 "video.mp4 empty" $T video_empty $O
  run 1 "frames.csv lists missing frames" $T frames_missing $O
  run 1 "frames.csv frame is a corrupt PNG" $T frames_corrupt $O
  # (track without init.csv detects the object: docs/detection.md; project needs a pose)
  run 1 "init.csv missing, no gt.csv (project)" project init_missing --frame 0 --out out.png
  run 1 "init.csv NaN translation" $T init_nan $O
  run 1 "init.csv zero quaternion" $T init_quat $O
  run 1 "init.csv header only" $T init_header $O
  run 1 "init.csv row with 7 columns" $T init_columns $O
  run 1 "gt.csv row with 4 columns" $T gt_columns $O
  run 1 "gt.csv frames out of order" $T gt_order $O
  run 1 "imu.csv NaN gyro" $T imu_nan --imu on $O
  run 0 "imu.csv saturated gyro (1e30 rad/s)" $T imu_saturated --imu on $O
  run 1 "imu.csv timestamps out of order" $T imu_order --imu on $O
  run 1 "imu.csv text in a number column" $T imu_text --imu on $O
  run 1 "score: poses file garbage" score cam_small poses_garbage.csv
  run 1 "replay: log missing" replay no_such.log
  run 1 "replay: log empty" replay can_empty.log
  run 0 "replay: last line cut short" replay can_truncated.log
  run 1 "replay: garbled log (video bytes)" replay can_garbled.log
  run 0 "replay: FD remote frame, DLC '_' with no digit" replay can_impossible.log
  run 0 "replay: a 10 kB line" replay can_long.log
  run 1 "replay --dbc: DBC missing" replay can_truncated.log --dbc no_such.dbc
  run 1 "replay --dbc: SG_ line cut short" replay can_truncated.log --dbc dbc_truncated.dbc
  run 1 "replay --dbc: byte order '@2'" replay can_truncated.log --dbc dbc_order.dbc
  run 0 "replay --dbc: signal beyond its 8-byte message" replay can_truncated.log --dbc dbc_beyond.dbc
  run 1 "replay --dbc: signal beyond any CAN FD frame" replay can_truncated.log --dbc dbc_beyond_fd.dbc
  run 1 "replay --dbc: comment never closed" replay can_truncated.log --dbc dbc_unclosed.dbc
  run 1 "replay --dbc: multiplexed signal, no multiplexor" replay can_truncated.log --dbc dbc_nomux.dbc
  run 1 "replay --dbc: garbled DBC (video bytes)" replay can_truncated.log --dbc dbc_garbled.dbc
  run 1 "replay --dbc: unknown --signal" replay can_truncated.log --dbc dbc_ok.dbc --signal M.b --plot out
  run 1 "sim: unknown scenario name" sim no_such_scenario --out out
  run 1 "sim: .scn garbage" sim scn_garbage.scn --out out
  run 1 "sim: .scn frames nan" sim scn_nan.scn --out out
  run 1 "sim: .scn unknown key" sim scn_unknown_key.scn --out out
  run 1 "run: configuration missing" run --config no_such.json
  run 1 "run: configuration not JSON" run --config run_notjson.json
  run 1 "run: configuration without model" run --config run_nokey.json
  run 1 "run: model is a number" run --config run_type.json
  run 1 "run: unknown head mode" run --config run_mode.json
  run 1 "run: misspelt key (camera.widht)" run --config run_unknown.json
  run 2 "option: unknown command" foo
  run 2 "option: no command" 
  run 2 "option: --every not a number" $T model_missing --out out --every nope
  run 2 "option: unknown option" $T model_missing --out out --colour
  run 2 "option: --out missing" $T model_missing
  run 1 "option: --mode unknown" $T cam_small --out out --mode fastest
  run 2 "option: sim --frames 0" sim can --out out --frames 0
  run 2 "option: score without POSES" score cam_small
}

table() {
  echo "| input | command | message (first line) | exit |"
  echo "|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
}

section() {
  cat <<'EOF'
## Bad inputs

What `epichead` says to bad input: each row is one input made by `tools/bad_inputs.sh` from
the teabox sequence (paths are relative to its scratch folder), the first line of what the
program printed, and its exit code: 1 a runtime error, 2 a command line that does not parse
(the usage line follows the message), 0 accepted with the problem counted in the report (a
candump log's malformed lines are skipped and counted, as candump tools do, and a log with no
frame at all is an error; IMU samples beyond any sensor's range are dropped and counted). No input crashes
or hangs the program. Regenerate with `tools/bad_inputs.sh [BIN]`; `ctest -R bad_inputs`
checks that the table is current. No command reads a DBC file: the DBC is checked against
the protocol tables by `tests/firmware_iface/test_dbc_agreement.cpp`.

EOF
  table
}

# The document with the section replaced (or appended): other sections are left as they are.
render() {
  local new="$1"
  if [[ ! -f "$doc" ]]; then
    printf '# Reliability\n\nHow epichead behaves on input it cannot use, and how that is tested.\n\n'
    cat "$new"
    return
  fi
  awk -v new="$new" '
    /^## Bad inputs[[:space:]]*$/ { while ((getline line < new) > 0) print line; skipping = 1; done = 1; next }
    skipping && /^## / { skipping = 0; print "" }
    !skipping { print }
    END { if (!done) { print ""; while ((getline line < new) > 0) print line } }
  ' "$doc"
}

section > "$W/.section"
render "$W/.section" > "$W/.doc"

status=0
if ((${#problems[@]})); then
  echo "bad_inputs: ${#problems[@]} input(s) crashed, hung or gave an unexpected exit code:" >&2
  printf '  %s\n' "${problems[@]}" >&2
  status=1
fi
if ((check)); then
  if ! diff -u "$doc" "$W/.doc" > "$W/.diff" 2>&1; then
    echo "bad_inputs: docs/reliability.md's Bad inputs table is not what the program gives now:" >&2
    cat "$W/.diff" >&2
    echo "bad_inputs: regenerate it with tools/bad_inputs.sh" >&2
    status=1
  fi
else
  mkdir -p "$(dirname "$doc")"
  cp "$W/.doc" "$doc"
  echo "bad_inputs: wrote ${#rows[@]} inputs into $doc"
fi
exit "$status"

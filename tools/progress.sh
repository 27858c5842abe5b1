# Progress of a long script, like the program's own (tools/progress.h): one line on stderr,
# rewritten in place — what is done of the total, the time taken so far and the time left — when
# stderr is a terminal, and nothing at all otherwise (a log, a pipe, CI). Sourced:
#
#   . "$here/tools/progress.sh"
#   progress_start LABEL TOTAL [UNIT]   # UNIT: what is counted (default "runs")
#   progress_say TEXT                   # TEXT on stdout on a line of its own; the progress line stays below
#   progress_step [N]                   # N more done (default 1)
#   progress_clear                      # wipes the line before a message on stderr
#   progress_end                        # the closing line (the time taken) and a newline
#
# Every function returns 0, so that a script under `set -e` goes on.

_progress_tty=0
_progress_label=""
_progress_unit="runs"
_progress_total=0
_progress_done=0
_progress_start=0
_progress_len=0

# _progress_now_us: microseconds on a clock that does not round the start (bash 5's EPOCHREALTIME, in
# microseconds; else SECONDS).
_progress_now_us() {
  if [[ -n "${EPOCHREALTIME:-}" ]]; then
    local t="${EPOCHREALTIME/[.,]/}"
    printf '%s' "$((10#$t))"
  else
    printf '%s' "$((SECONDS * 1000000))"
  fi
}

# _progress_duration S: "m:ss" or "h:mm:ss".
_progress_duration() {
  local s="$1"
  if ((s >= 3600)); then
    printf '%d:%02d:%02d' $((s / 3600)) $((s / 60 % 60)) $((s % 60))
  else
    printf '%d:%02d' $((s / 60)) $((s % 60))
  fi
}

# _progress_line [final]: the text of the line now.
_progress_line() {
  local elapsed=$((($(_progress_now_us) - _progress_start) / 1000000))
  local line="$_progress_label: $_progress_done/$_progress_total $_progress_unit  $(_progress_duration "$elapsed")"
  if [[ "${1:-}" == final ]]; then
    line+=" taken"
  else
    line+=" elapsed"
    if ((_progress_done > 0 && _progress_done < _progress_total)); then
      line+="  $(_progress_duration $((elapsed * (_progress_total - _progress_done) / _progress_done))) left"
    fi
  fi
  printf '%s' "$line"
}

# _progress_draw [final]: '\r', the line, blanks over the rest of a longer earlier one.
_progress_draw() {
  if ((!_progress_tty)); then return 0; fi
  local line
  line="$(_progress_line "${1:-}")"
  printf '\r%-*s' "$_progress_len" "$line" >&2
  _progress_len=${#line}
  if [[ "${1:-}" == final ]]; then
    printf '\n' >&2
    _progress_len=0
  fi
  return 0
}

progress_start() {
  _progress_label="$1"
  _progress_total="$2"
  _progress_unit="${3:-runs}"
  _progress_done=0
  _progress_start=$(_progress_now_us)
  _progress_len=0
  if [[ -t 2 ]]; then _progress_tty=1; else _progress_tty=0; fi
  _progress_draw
}

progress_step() {
  _progress_done=$((_progress_done + ${1:-1}))
  _progress_draw
}

# progress_clear: wipes the line (another message goes there); the next drawing puts it back.
progress_clear() {
  if ((_progress_tty && _progress_len > 0)); then printf '\r%*s\r' "$_progress_len" '' >&2; fi
  _progress_len=0
  return 0
}

progress_say() {
  progress_clear
  printf '%s\n' "$*"
  _progress_draw
}

progress_end() {
  _progress_draw final
}

#!/usr/bin/env bash
# render_stop.sh SOFTTLED PNG_PROBE DATA
# SIGTERM during `softtled render`: exit 143, a line saying how many PNGs were written,
# exactly that many PNGs, each complete (png_probe decodes it), no temporary files.
# Skipped (77) where no offscreen OpenGL (EGL) exists.
set -u
exe=$1 probe=$2 data=$3
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; echo "--- log"; cat "$tmp/log.txt"; exit 1; }
at=$(seq -s, 0 0.2 200)  # 1001 frames, 8000 steps apart
"$exe" render --scene "$data/surface.toml" --at "$at" --size 64x64 --samples 0 --backend cpu --out "$tmp/png" \
  >"$tmp/log.txt" 2>&1 &
pid=$!
for _ in $(seq 1200); do
  [ "$(ls "$tmp/png" 2>/dev/null | grep -c '\.png$')" -ge 2 ] && break
  if ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid"
    if grep -q -e "no EGL display" -e "no EGL backend" -e "GL context" "$tmp/log.txt"; then
      echo "SKIP: no offscreen OpenGL (EGL) here"; cat "$tmp/log.txt"; exit 77
    fi
    pid=
    fail "render ended before the signal"
  fi
  sleep 0.1
done
kill -TERM "$pid"
wait "$pid"
rc=$?
pid=
[ "$rc" -eq 143 ] || fail "exit code $rc, wanted 143"
n=$(sed -n 's/.*; \([0-9]*\) complete PNGs in .*/\1/p' "$tmp/log.txt")
[ -n "$n" ] || fail "no 'complete PNGs' line"
[ "$(ls "$tmp/png" | grep -c '\.png$')" -eq "$n" ] || fail "$n PNGs reported, $(ls "$tmp/png")"
[ "$(ls "$tmp/png" | grep -vc '\.png$')" -eq 0 ] || fail "other files left: $(ls "$tmp/png")"
for f in "$tmp"/png/*.png; do "$probe" "$f" >/dev/null || fail "$f does not decode"; done
echo "ok: SIGTERM -> 143 with $n complete PNGs"

# Two signals at once during `render --video`: the second ends softtled at once, and nothing
# it was writing outlives it: no PATH.tmp (ffmpeg, in its own process group, had finished
# it after softtled was gone), no ffmpeg log, no ffmpeg still running.
if command -v ffmpeg >/dev/null; then
  logs_before=$(ls /tmp/softtled-ffmpeg-* 2>/dev/null | wc -l)
  "$exe" render --scene "$data/surface.toml" --set time.lambda=0.002 --video "$tmp/v.mp4" --to 50 --fps 100 \
    --size 64x48 --backend cpu >"$tmp/log.txt" 2>&1 &
  pid=$!
  for _ in $(seq 300); do grep -q "video" "$tmp/log.txt" 2>/dev/null && break; sleep 0.1; done
  sleep 1
  # Two different signals: two of the same may reach the process as one (standard signals
  # do not queue), and the clean stop would run. The second ends it at once, by its own
  # default action (whichever arrives second).
  kill -TERM "$pid"; kill -INT "$pid"
  wait "$pid"
  rc=$?
  pid=
  [ "$rc" -eq 130 ] || [ "$rc" -eq 143 ] || fail "video, two signals: exit code $rc, wanted 130 or 143"
  grep -q "rendered so far" "$tmp/log.txt" && fail "video, two signals: the clean stop ran (one signal seen)"
  [ -e "$tmp/v.mp4" ] && fail "video, two signals: v.mp4 written by a clean stop"
  sleep 1
  [ -e "$tmp/v.mp4.tmp" ] && fail "video, two signals: v.mp4.tmp left"
  [ "$(ls /tmp/softtled-ffmpeg-* 2>/dev/null | wc -l)" -le "$logs_before" ] || fail "video, two signals: ffmpeg's log left"
  pgrep -f "ffmpeg.*$tmp/v.mp4.tmp" | xargs -r ps -o stat= -p | grep -qv Z && fail "video, two signals: ffmpeg still running"
  echo "ok: two signals during a video leave no temporary, log or ffmpeg behind"
fi

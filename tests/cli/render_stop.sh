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

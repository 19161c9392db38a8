#!/usr/bin/env bash
# `softtled render` end to end: two PNGs of the coarse torus, the renderer string and the
# frame time printed, the body visible in the frames, bad --at rejected with exit code 2.
# Usage: render_cli.sh SOFTTLED PNG_PROBE ASSETS OUT_DIR. Exit 77 (skip) without EGL.
set -u
exe=$1 probe=$2 assets=$3 out=$4
rm -rf "$out" && mkdir -p "$out"
fail() { echo "FAIL: $*"; echo "--- log"; cat "$out/log.txt"; exit 1; }

"$exe" render --scene "$assets/scenes/torus_drop.toml" --at 0,0.025 --size 200x150 --out "$out" \
  --set 'body.segments=[45,9]' >"$out/log.txt" 2>&1
rc=$?
if [ $rc -ne 0 ]; then
  if grep -q -e "no EGL display" -e "no EGL backend" "$out/log.txt"; then
    echo "SKIP: no offscreen OpenGL (EGL) here"; cat "$out/log.txt"; exit 77
  fi
  fail "softtled render exited with $rc"
fi
grep -q "^GL renderer: " "$out/log.txt" || fail "no 'GL renderer:' line"
grep -q "^frame time: " "$out/log.txt" || fail "no 'frame time:' line"
for t in 0.0000 0.0250; do
  png="$out/torus_drop_t$t.png"
  [ -s "$png" ] || fail "$png not written"
  frac=$("$probe" "$png" | sed -n 's/^body_frac=//p')
  awk -v f="$frac" 'BEGIN { exit !(f > 0.02) }' || fail "$png: body covers only $frac of the frame"
done

"$exe" render --scene "$assets/scenes/torus_drop.toml" --at 0.02,0.01 --out "$out/bad" >"$out/bad.txt" 2>&1
rc=$?
[ $rc -eq 2 ] || { cat "$out/bad.txt"; fail "decreasing --at: expected exit code 2, got $rc"; }
grep -q "increasing" "$out/bad.txt" || fail "decreasing --at: message does not say why"
cat "$out/log.txt"
echo "PASS"

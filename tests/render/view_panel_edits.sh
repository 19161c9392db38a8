#!/usr/bin/env bash
# The viewer's panel edits and its output names, under Xvfb with xdotool (`softtled view`,
# paused, 50 steps per N):
# * an E the simulation refuses (Ctrl+click, 1e-30) is logged naming "E [Pa]", the panel
#   goes back to the live E, so the next edit (nu) is taken, not refused for the bad E; E
#   typed past its range (3.0001e34) is held to 1e12 Pa and taken;
# * the closing line counts every step (N N, E changed, N: 150), not those since dt changed;
# * P writes softtled_view_001.png beside an earlier session's softtled_view_000.png,
#   which it leaves as it was.
# Usage: view_panel_edits.sh SOFTTLED ASSETS OUT_DIR. Exit 77 (skip) without xvfb-run or xdotool.
set -u
exe=$1 assets=$2 out=$3
for tool in xvfb-run xdotool; do
  command -v $tool >/dev/null || { echo "SKIP: $tool not installed"; exit 77; }
done
rm -rf "$out" && mkdir -p "$out"
echo "an earlier session's screenshot" >"$out/softtled_view_000.png"

cat >"$out/drive.sh" <<INNER
#!/usr/bin/env bash
set -u
log="$out/view.log"
fail() { echo "FAIL: \$*"; echo "--- viewer log"; cat "\$log"; kill \$pid 2>/dev/null; exit 1; }
source "$(cd "$(dirname "$0")" && pwd)/viewer_drive.sh"
"$exe" view --backend cpu --size 1280x800 --scene "$assets/scenes/torus_coarse.toml" --paused --substeps 50 \\
  --screenshot-dir "$out" --quit-after 120 >"\$log" 2>&1 &
pid=\$!
wait_first_frame
xdotool mousemove 1000 100 click 1  # keyboard focus (the sky: an orbit by nothing)
sleep 0.3
# Ctrl+click a panel slider at (x, y), type a value, Enter (held over a frame: Dear ImGui
# 1.86 misses a press and release within one). ImGui applies each prefix as it is typed.
typed() {
  xdotool mousemove \$1 \$2 keydown ctrl click 1 keyup ctrl
  sleep 0.5
  xdotool type --delay 150 "\$3"
  xdotool keydown Return; sleep 0.3; xdotool keyup Return
  sleep 0.5
  xdotool mousemove 1000 100
  sleep 0.3
}
step() { xdotool key n; sleep 0.7; }
step; step
typed 110 341 1e-30       # E [Pa]: refused (its prefix 1e-3 is taken)
for i in \$(seq 50); do grep -q "refused" "\$log" && break; sleep 0.1; done
[ -n "\${SHOT:-}" ] && import -window root "$out/refused.png"
typed 110 381 0.45        # nu, a warning line lower
typed 110 341 3.0001e34   # E [Pa]: held to 1e12
step
[ -n "\${SHOT:-}" ] && import -window root "$out/end.png"
screenshot_and_quit
INNER

xvfb-run -a -s "-screen 0 1280x800x24" bash "$out/drive.sh" || exit 1
log="$out/view.log"
fail() { echo "FAIL: $*"; exit 1; }
grep -q "E \[Pa\] = 1e-30 refused" "$log" || fail "the refused E was not logged naming E [Pa]"
[ "$(grep -c refused "$log")" = 1 ] || fail "more than the one bad E was refused (the nu edit after it?)"
# (nu's value is not checked: on a loaded machine at 6 fps ImGui takes typed digits out of
# order, a CI run ended at nu = 0.247; that the edit was taken, not refused, is the one
# "refused" line above; test_viewer_live checks the value.)
grep -q "live material at close: E = 1e+12 Pa," "$log" || fail "E typed past its range was not held to 1e12 Pa"
grep -q "closed at t = .* after 150 steps" "$log" || fail "the closing line does not count all 150 steps"
grep -q "screenshot .*softtled_view_001.png" "$log" || fail "P did not write softtled_view_001.png"
[ "$(cat "$out/softtled_view_000.png")" = "an earlier session's screenshot" ] || fail "P overwrote softtled_view_000.png"
head -c 8 "$out/softtled_view_001.png" | grep -q PNG || fail "softtled_view_001.png is not a PNG"
echo "PASS"

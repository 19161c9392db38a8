#!/usr/bin/env bash
# The viewer tested as a person would, under Xvfb: start `softtled view`, wait for the
# first frame, click on the body and pull it, press F (friction: sliding -> static) and
# ] twice (slope on, 20 -> 30 deg), M (re-mesh with TetGen), take a screenshot of the X
# screen, P (the viewer's own screenshot), quit with Esc.
# Passes when the viewer logged each input, exited cleanly, and the screenshot shows the
# body (orange pixels right of the panel, above the plot window) and the panel (dark pixels, ImGui blue headers).
# The body is the stable Neo-Hookean model: the pull is as hard as the mouse moves, and
# under CI load (fewer steps per frame, so a longer stretch per step) it could crush an
# element of the classic model inside out; the watchdog then stops the run and releases the
# drag itself (test_watchdog_health covers that path), and this test is about the inputs.
# Usage: view_smoke.sh SOFTTLED PNG_PROBE ASSETS OUT_DIR. Exit 77 (skip) when xvfb-run,
# xdotool or ImageMagick's import is missing.
set -u
exe=$1 probe=$2 assets=$3 out=$4
for tool in xvfb-run xdotool import; do
  command -v $tool >/dev/null || { echo "SKIP: $tool not installed"; exit 77; }
done
rm -rf "$out" && mkdir -p "$out"

cat >"$out/drive.sh" <<INNER
#!/usr/bin/env bash
set -u
log="$out/view.log"
fail() { echo "FAIL: \$*"; echo "--- viewer log"; cat "\$log"; kill \$pid 2>/dev/null; exit 1; }
source "$(cd "$(dirname "$0")" && pwd)/viewer_drive.sh"
"$exe" view --backend cpu --size 1280x800 --scene "$assets/scenes/torus_drop.toml" --set 'body.segments=[45,9]' \\
  --set material.model=stable_neo_hookean \\
  --screenshot-dir "$out" --quit-after 120 >"\$log" 2>&1 &
pid=\$!
wait_first_frame
import -window root "$out/start.png" || fail "import failed"
# Find the body on screen as a person would, and grab its left rim.
read bx0 by0 bx1 by1 < <("$probe" "$out/start.png" 380 0 1280 550 | sed -n 's/^body_bbox=//p' | tr , ' ')
[ -n "\${bx0:-}" ] || fail "no body on the first screenshot"
x=\$(( bx0 + (bx1 - bx0) / 12 )); y=\$(( (by0 + by1) / 2 ))
xdotool mousemove \$x \$y mousedown 1
sleep 0.3
xdotool mousemove \$x \$(( y - 40 ))
sleep 1
xdotool mouseup 1
xdotool mousemove 1000 100
xdotool key f
xdotool key bracketright
sleep 0.2
xdotool key bracketright
sleep 0.5
xdotool key m
for i in \$(seq 200); do grep -q -e "re-meshed" -e "re-mesh failed" "\$log" && break; sleep 0.1; done
sleep 3
import -window root "$out/screen.png" || fail "import failed"
screenshot_and_quit
INNER

xvfb-run -a -s "-screen 0 1280x800x24" bash "$out/drive.sh" || exit 1
log="$out/view.log"
fail() { echo "FAIL: $*"; exit 1; }
grep -q "picked node" "$log" || fail "clicking the body did not pick it"
grep -q "released" "$log" || fail "releasing the mouse did not release the body"
grep -q "contact mode static" "$log" || fail "F did not switch to static friction"
grep -q "slope on at 30.0 deg" "$log" || fail "] ] did not turn the slope to 30 deg"
grep -q "screenshot .*softtled_view_000.png" "$log" || fail "P did not write a screenshot"
grep -q "re-meshed in" "$log" || fail "M did not re-mesh"

check() {  # check PNG: body right of the panel, panel on the left
  local png=$1 scene panel
  scene=$("$probe" "$png" 380 0 1280 550)  # above the plot window
  panel=$("$probe" "$png" 10 10 365 790)
  local body=$(echo "$scene" | sed -n 's/^body_frac=//p')
  local dark=$(echo "$panel" | sed -n 's/^dark_frac=//p')
  local blue=$(echo "$panel" | sed -n 's/^ui_blue_frac=//p')
  echo "$png: body $body of the scene area; panel dark $dark, headers $blue"
  awk -v f="$body" 'BEGIN { exit !(f > 0.01) }' || fail "$png: the body is not visible (body_frac $body)"
  awk -v f="$dark" 'BEGIN { exit !(f > 0.4) }' || fail "$png: no panel background (dark_frac $dark)"
  awk -v f="$blue" 'BEGIN { exit !(f > 0.02) }' || fail "$png: no panel headers (ui_blue_frac $blue)"
}
check "$out/screen.png"
check "$out/softtled_view_000.png"
echo "PASS"

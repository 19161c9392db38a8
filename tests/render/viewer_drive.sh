# Shared by the Xvfb viewer tests' drive scripts (view_smoke.sh, view_panel_edits.sh),
# sourced after they set $log (the viewer's log) and fail(); $pid (its process) before use.
# The viewer's first frame within 30 s, then a second for it to settle.
wait_first_frame() {
  for i in $(seq 300); do
    grep -q "first frame drawn" "$log" && break
    kill -0 "$pid" 2>/dev/null || fail "viewer exited before its first frame"
    sleep 0.1
  done
  grep -q "first frame drawn" "$log" || fail "no first frame within 30 s"
  sleep 1
}
# P for a screenshot, then Esc; the viewer must be gone within 20 s with exit 0.
screenshot_and_quit() {
  xdotool key p
  for i in $(seq 100); do grep -q "screenshot " "$log" && break; sleep 0.1; done
  xdotool key Escape
  for i in $(seq 200); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -0 "$pid" 2>/dev/null && fail "viewer still running 20 s after Esc"
  wait "$pid"
  local rc=$?
  [ $rc -eq 0 ] || fail "viewer exited with $rc"
  cat "$log"
}

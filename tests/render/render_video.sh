#!/usr/bin/env bash
# `softtled render --video` end to end: a short video of the coarse torus whose frame count
# (ffprobe, decoded) is fps x (to - from) / speed (+-1) and whose duration is (to - from) /
# speed (+- one frame); its errors (bad range, unwritable path, no ffmpeg, ffmpeg failing)
# exit with a message and leave no file; and the viewer's recording (--record) under Xvfb
# writes as many frames as the simulated time it ran at 60 fps.
# Usage: render_video.sh SOFTTLED ASSETS OUT_DIR. Exit 77 (skip) without ffmpeg/ffprobe or EGL.
set -u
exe=$1 assets=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
fail() { echo "FAIL: $*"; for f in "$out"/*.txt; do echo "--- $f"; cat "$f"; done; exit 1; }
for tool in ffmpeg ffprobe; do
  command -v $tool >/dev/null || { echo "SKIP: no $tool (Debian's ffmpeg; scripts/setup.sh installs it)"; exit 77; }
done
scene="$assets/scenes/torus_drop.toml"
common=(--scene "$scene" --set 'body.segments=[45,9]' --size 161x120 --color displacement)

# frame count and duration: 60 fps, 0.02 .. 0.12 s at half speed -> 12 frames, 0.2 s
fps=60 from=0.02 to=0.12 speed=0.5
"$exe" render "${common[@]}" --video "$out/drop.mp4" --fps $fps --from $from --to $to --speed $speed >"$out/log.txt" 2>&1
rc=$?
if [ $rc -ne 0 ]; then
  grep -q -e "no EGL display" -e "no EGL backend" "$out/log.txt" && { echo "SKIP: no offscreen OpenGL (EGL)"; exit 77; }
  fail "softtled render --video exited with $rc"
fi
[ -s "$out/drop.mp4" ] || fail "drop.mp4 not written"
[ -e "$out/drop.mp4.tmp" ] && fail "drop.mp4.tmp left behind"
# A symlink at the path stays one (its target is replaced) and keeps the target's mode, as
# every atomic output does.
echo old >"$out/kept.mp4" && chmod 640 "$out/kept.mp4" && ln -sf kept.mp4 "$out/alias.mp4"
"$exe" render "${common[@]}" --video "$out/alias.mp4" --to 0.02 >"$out/alias.txt" 2>&1 || fail "render --video onto a symlink"
[ -L "$out/alias.mp4" ] && [ "$(stat -c %a "$out/kept.mp4")" = 640 ] && [ "$(head -c 3 "$out/kept.mp4")" != old ] ||
  fail "render --video replaced the symlink or the target's mode: $(ls -l "$out/alias.mp4" "$out/kept.mp4")"
frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$out/drop.mp4")
duration=$(ffprobe -v error -show_entries format=duration -of csv=p=0 "$out/drop.mp4")
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=s=x:p=0 "$out/drop.mp4")
expected=$(awk -v f=$fps -v a=$from -v b=$to -v s=$speed 'BEGIN { printf "%.6f", f * (b - a) / s }')
echo "video: $frames frames, $duration s, $size (expected $expected frames, $(awk -v e="$expected" -v f=$fps 'BEGIN{print e/f}') s)"
awk -v n="$frames" -v e="$expected" 'BEGIN { d = n - e; exit !(d <= 1 && d >= -1) }' || fail "$frames frames, expected $expected +- 1"
awk -v d="$duration" -v e="$expected" -v f=$fps 'BEGIN { x = d - e / f; exit !(x <= 1 / f && x >= -1 / f) }' ||
  fail "duration $duration s, expected $(awk -v e="$expected" -v f=$fps 'BEGIN{print e/f}') s"
[ "$size" = "162x120" ] || fail "video size $size, expected 162x120 (161 padded to even)"

# errors: exit code, message, no file
expect_error() {  # CODE PATTERN NAME ARGS...
  local code=$1 pattern=$2 name=$3; shift 3
  "$@" >"$out/err_$name.txt" 2>&1
  local rc=$?
  [ $rc -eq "$code" ] || fail "$name: expected exit code $code, got $rc"
  grep -q -e "$pattern" "$out/err_$name.txt" || fail "$name: message does not say '$pattern'"
}
expect_error 2 "after --from" range "$exe" render "${common[@]}" --video "$out/e1.mp4" --from 0.2 --to 0.1
expect_error 2 "fps" fps "$exe" render "${common[@]}" --video "$out/e2.mp4" --to 0.1 --fps 0
expect_error 2 "does not exist" path "$exe" render "${common[@]}" --video "$out/no/such/dir/e3.mp4" --to 0.1
expect_error 2 ".mp4, .mov or .mkv" ext "$exe" render "${common[@]}" --video "$out/e4.avi" --to 0.1
expect_error 5 "ffmpeg not found" noffmpeg env PATH=/nonexistent "$exe" render "${common[@]}" --video "$out/e5.mp4" --to 0.1
# an ffmpeg that writes half a file and fails: the error carries its message, nothing is left
mkdir -p "$out/fakebin"
cat >"$out/fakebin/ffmpeg" <<'FAKE'
#!/bin/sh
for last; do :; done
echo partial >"$last"
head -c 1000 >/dev/null
echo "fake ffmpeg: encoder exploded" >&2
exit 1
FAKE
chmod +x "$out/fakebin/ffmpeg"
expect_error 5 "encoder exploded" ffmpegfails env PATH="$out/fakebin:$PATH" "$exe" render "${common[@]}" --video "$out/e6.mp4" --to 0.1
for f in e1 e2 e3 e4 e5 e6; do
  [ -e "$out/$f.mp4" ] || [ -e "$out/$f.mp4.tmp" ] && fail "$f: a file was left behind"
done

# the viewer's recording: --record, closed after a few seconds; frames = simulated time x 60 + 1
if command -v xvfb-run >/dev/null; then
  xvfb-run -a -s "-screen 0 1024x768x24" "$exe" view --scene "$scene" --set 'body.segments=[45,9]' --size 640x400 \
    --color displacement --record "$out/view.mp4" --quit-after 4 --screenshot-dir "$out" >"$out/view.txt" 2>&1 ||
    fail "softtled view --record failed"
  t=$(sed -n 's/^view: closed at t = \([0-9.]*\) s.*/\1/p' "$out/view.txt")
  n=$(sed -n 's/^view: recording window closed (.*: \([0-9]*\) frames.*/\1/p' "$out/view.txt")
  vframes=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$out/view.mp4")
  echo "viewer: simulated $t s, recorded $n frames, ffprobe $vframes frames"
  [ -n "$t" ] && [ -n "$n" ] || fail "viewer log has no closing time or frame count"
  [ "$vframes" = "$n" ] || fail "viewer video has $vframes frames, the viewer wrote $n"
  awk -v n="$n" -v t="$t" 'BEGIN { e = int(t * 60) + 1; exit !(n >= e - 1 && n <= e + 1 && n > 1) }' ||
    fail "viewer recorded $n frames for $t s of simulated time at 60 fps"
else
  echo "no xvfb-run: viewer recording not checked"
fi
cat "$out/log.txt"
echo "PASS"

#!/usr/bin/env bash
# abrupt_signals.sh SOFTTLED DATA
# Signals that end softtled at once rather than stop it, during `render --video`: SIGPIPE
# (standard output's reader gone, `render --video v.mp4 | head -1`) and SIGQUIT. The
# program still dies of that signal (exit 141 / 131), but first removes v.mp4.tmp and
# ffmpeg's log and kills ffmpeg's process group (both had outlived it: neither signal was
# handled). Skipped (77) where no offscreen OpenGL (EGL) or no ffmpeg exists.
set -u
exe=$1 data=$2
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; exec 3<&- 2>/dev/null; rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cp "$data/surface.toml" "$data/tetrahedron.obj" .
command -v ffmpeg >/dev/null || { echo "SKIP: no ffmpeg"; exit 77; }
status=0
fail() { echo "FAIL: $*"; status=1; }
video=(render --scene surface.toml --video v.mp4 --to 200 --size 64x64 --samples 0 --backend cpu)

# Waits (at most 120 s) for softtled ($pid) to have ffmpeg running and v.mp4.tmp written;
# sets ff (ffmpeg's pid) and log (its log file). Returns 77 where rendering cannot start.
started() {
  ff= log=
  for _ in $(seq 1200); do
    ff=$(pgrep -P "$pid" -x ffmpeg | head -1)
    if [ -n "$ff" ] && [ -s v.mp4.tmp ]; then
      log=$(readlink "/proc/$ff/fd/2")
      return 0
    fi
    if ! kill -0 "$pid" 2>/dev/null; then
      grep -q -e "no EGL display" -e "no EGL backend" -e "GL context" err.txt && return 77
      return 1
    fi
    sleep 0.1
  done
  return 1
}
# After softtled died: nothing of the video left, ffmpeg dead (gone or a zombie).
clean() {
  for _ in $(seq 50); do
    { [ ! -e "/proc/$ff" ] || [ "$(awk '{print $3}' "/proc/$ff/stat" 2>/dev/null)" = Z ]; } && break
    sleep 0.1
  done
  [ ! -e v.mp4.tmp ] && [ ! -e v.mp4 ] || fail "$1: the video's temporary was left: $(ls v.mp4*)"
  case "$log" in
    /tmp/softtled-ffmpeg-*) [ ! -e "$log" ] || fail "$1: ffmpeg's log $log was left" ;;
    *) fail "$1: no log found" ;;
  esac
  { [ ! -e "/proc/$ff" ] || [ "$(awk '{print $3}' "/proc/$ff/stat" 2>/dev/null)" = Z ]; } ||
    { fail "$1: ffmpeg ($ff) outlived softtled"; kill -KILL "$ff" 2>/dev/null; }
}

# SIGPIPE: standard output is a FIFO whose reader goes away once rendering runs (-v: a
# line per frame, flushed).
mkfifo so
"$exe" -v "${video[@]}" >so 2>err.txt &
pid=$!
exec 3<so
started
r=$?
[ $r -eq 77 ] && { echo "SKIP: no offscreen OpenGL (EGL) here"; cat err.txt; exit 77; }
if [ $r -eq 0 ]; then
  exec 3<&-
  wait "$pid"
  rc=$?
  pid=
  [ $rc -eq 141 ] || fail "SIGPIPE: exit $rc, wanted 141"
  clean SIGPIPE
else
  fail "SIGPIPE: the video never started"; cat err.txt
fi

# SIGQUIT (job control on: a background job of a script would ignore it; no core file).
rm -f v.mp4.tmp
ulimit -c 0
set -m
"$exe" "${video[@]}" >out.txt 2>err.txt &
pid=$!
set +m
if started; then
  kill -QUIT "$pid"
  wait "$pid"
  rc=$?
  pid=
  [ $rc -eq 131 ] || fail "SIGQUIT: exit $rc, wanted 131"
  clean SIGQUIT
else
  fail "SIGQUIT: the video never started"; cat err.txt
fi
[ $status -eq 0 ] && echo "ok: SIGPIPE and SIGQUIT end softtled with no temporary, log or ffmpeg left"
exit $status

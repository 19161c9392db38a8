#!/usr/bin/env bash
# blocked_write_stop.sh SOFTTLED DATA ASSETS
# The first SIGINT / SIGTERM / SIGHUP stops a command whose output write is blocked on a
# reader that does not read: `run --csv FIFO` and `run --csv -` into a stalled pipe
# (each blocked in write(2) for ever, restarted after the signal: only a second signal
# ended it, without its closing line), and `mesh --vtu FIFO`. Each exits 130 / 143 / 129
# within a few seconds with a "stopped by signal" line. And `mesh` answers a signal as run
# does (it had no handler: killed mid-write, a partial NAME.tmp and no word): a line
# saying what it wrote, exit 130, no temporary left.
set -u
exe=$1 data=$2 assets=$3
tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cp "$data/surface.toml" "$data/tetrahedron.obj" .
status=0
fail() { echo "FAIL: $*"; status=1; }
waited="stopped while the write waited for its reader to read"
# A row per step for 1000 s: the pipe (64 KiB) is full within a fraction of a second.
long=(--scene surface.toml --set time.duration=1000 --set time.output_every=1e-9)
# Waits (at most 60 s) until process $1 sleeps in a pipe write.
blocked() {
  for _ in $(seq 600); do
    grep -q pipe_write "/proc/$1/wchan" 2>/dev/null && return 0
    kill -0 "$1" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
# Waits (at most 10 s) for process $1 to end; its exit status in $rc, 999 if it did not.
ended() {
  rc=999
  for _ in $(seq 100); do
    kill -0 "$1" 2>/dev/null || { wait "$1"; rc=$?; return 0; }
    sleep 0.1
  done
  kill -KILL "$1" 2>/dev/null
  wait "$1"
  return 1
}

# run --csv FIFO whose reader holds it open and reads nothing.
mkfifo ff
sleep 120 <ff &
reader=$!
pids+=("$reader")
"$exe" run "${long[@]}" --csv ff >out1.txt 2>err1.txt &
p=$!
pids+=("$p")
if blocked "$p"; then
  kill -INT "$p"
  ended "$p" || fail "run --csv FIFO: still blocked 10 s after SIGINT"
  [ "$rc" -eq 130 ] && grep -q "^softtled: stopped by signal 2 (ff: $waited" err1.txt ||
    { fail "run --csv FIFO: exit $rc, wanted 130 and a stop line"; cat err1.txt; }
else
  fail "run --csv FIFO never blocked on its reader"
fi
kill "$reader" 2>/dev/null

# run --csv - into a pipe whose reader reads nothing: SIGTERM and SIGHUP.
for sig in TERM:143:15 HUP:129:1; do
  IFS=: read -r name want num <<<"$sig"
  rm -f pid rc
  ( "$exe" run "${long[@]}" --csv - 2>err2.txt & echo $! >pid; wait $!; echo $? >rc ) | sleep 120 &
  reader=$!  # the pipeline's last process
  pids+=("$reader")
  for _ in $(seq 100); do [ -s pid ] && break; sleep 0.1; done
  p=$(cat pid)
  pids+=("$p")
  if blocked "$p"; then
    kill -"$name" "$p"
    for _ in $(seq 100); do [ -s rc ] && break; sleep 0.1; done
    got=$(cat rc 2>/dev/null || echo "none: still blocked 10 s after SIG$name")
    [ "$got" = "$want" ] && grep -q "^softtled: stopped by signal $num (standard output: $waited" err2.txt ||
      { fail "run --csv - into a stalled pipe, SIG$name: exit $got, wanted $want and a stop line"; cat err2.txt; }
  else
    fail "run --csv - never blocked on its pipe"
  fi
  kill -KILL "$p" 2>/dev/null
  kill "$reader" 2>/dev/null
  wait "$reader" 2>/dev/null
done

# mesh --write BASE --vtu FIFO (the files are written whole; the VTU, larger than the pipe,
# blocks on its reader): SIGINT names the files written.
mkfifo mf
sleep 120 <mf &
reader=$!
pids+=("$reader")
"$exe" mesh --scene "$assets/scenes/torus_coarse.toml" --set 'body.segments=[90,18]' --write m --vtu mf \
  >out3.txt 2>err3.txt &
p=$!
pids+=("$p")
if blocked "$p"; then
  kill -INT "$p"
  ended "$p" || fail "mesh --vtu FIFO: still blocked 10 s after SIGINT"
  [ "$rc" -eq 130 ] && grep -q "^softtled: stopped by signal 2; wrote m.node and m.ele$" err3.txt ||
    { fail "mesh --vtu FIFO: exit $rc, wanted 130 and 'wrote m.node and m.ele'"; cat err3.txt; }
else
  fail "mesh --vtu FIFO never blocked on its reader"
fi
kill "$reader" 2>/dev/null

# mesh of a large torus, SIGINT while TetGen meshes or while the files are written: a line
# saying which were written whole, exit 130, no NAME.tmp left.
"$exe" mesh --scene "$assets/scenes/torus_coarse.toml" --set 'body.segments=[300,60]' --write big --vtu big.vtu \
  >out4.txt 2>err4.txt &
p=$!
pids+=("$p")
sleep 1
kill -INT "$p" 2>/dev/null
wait "$p"
rc=$?
[ "$rc" -eq 130 ] && grep -q "^softtled: stopped by signal 2; wrote " err4.txt ||
  { fail "mesh: SIGINT gave exit $rc, wanted 130 and a line saying what was written"; cat err4.txt; }
ls ./*.tmp >/dev/null 2>&1 && fail "temporaries left: $(ls ./*.tmp)"
for f in $(sed -n 's/^softtled: stopped by signal 2; wrote \(big.*\)$/\1/p' err4.txt | sed 's/,\| and / /g'); do
  [ -s "$f" ] || fail "mesh said it wrote $f"
done

[ $status -eq 0 ] && echo "ok: a write blocked on its reader stops on the first signal; mesh stops as run does"
exit $status

#!/usr/bin/env bash
# signal_stop.sh SOFTTLED DATA [TORUS_SCENE]
# SIGTERM and SIGINT during `run --csv --vtu`: the run finishes its step, exits 143 / 130,
# says what it wrote, and leaves only complete output: every CSV row whole (the field
# count of the header, the file ends with a newline), as many rows as it reported, every
# frame a complete .vtu listed by a parseable series.pvd, no temporary files. The run is
# long enough for the wall-time warning, which must come first.
set -u
exe=$1 data=$2 torus=${3:-}
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; echo "--- stderr"; cat "$tmp/err.txt"; exit 1; }

stop_run() {  # SIGNAL EXPECTED_CODE
  local sig=$1 want=$2
  rm -rf "$tmp/vtu" "$tmp/out.csv" "$tmp/err.txt"
  "$exe" run --scene "$data/surface.toml" --set time.duration=1e5 --set time.output_every=0.01 \
    --csv "$tmp/out.csv" --vtu "$tmp/vtu" --every 100 >"$tmp/out.txt" 2>"$tmp/err.txt" &
  pid=$!
  # Wait (at most 120 s) for the warning and for a few frames.
  for _ in $(seq 1200); do
    if grep -q "warning: this run will take about" "$tmp/err.txt" && [ "$(ls "$tmp/vtu" 2>/dev/null | grep -c '\.vtu$')" -ge 3 ]; then
      break
    fi
    kill -0 "$pid" 2>/dev/null || fail "run ended before the signal"
    sleep 0.1
  done
  grep -q "warning: this run will take about" "$tmp/err.txt" || fail "no wall-time warning for a run of 1e5 s"
  kill -"$sig" "$pid"
  wait "$pid"
  local rc=$?
  pid=
  [ "$rc" -eq "$want" ] || fail "SIG$sig: exit code $rc, wanted $want"
  grep -q "softtled: stopped by signal" "$tmp/err.txt" || fail "SIG$sig: no 'stopped by signal' message"
  local rows
  rows=$(sed -n 's/.*wrote \([0-9]*\) CSV rows to.*/\1/p' "$tmp/err.txt")
  [ -n "$rows" ] || fail "SIG$sig: the message does not say how many rows were written"
  python3 - "$tmp/out.csv" "$rows" "$tmp/vtu" <<'PY' || fail "SIG$sig: incomplete output"
import os, sys, xml.etree.ElementTree as ET
csv, rows, vtu = sys.argv[1], int(sys.argv[2]), sys.argv[3]
data = open(csv).read()
assert data.endswith("\n"), "CSV does not end with a newline (half-written row)"
lines = data.splitlines()
n = len(lines[0].split(","))
for i, l in enumerate(lines):
    assert len(l.split(",")) == n, f"CSV line {i + 1} has {len(l.split(','))} fields, header {n}"
    if i: [float(x) for x in l.split(",")]
assert len(lines) - 1 == rows, f"{len(lines) - 1} rows in the CSV, {rows} reported"
assert rows >= 3, f"only {rows} rows"
left = [f for f in os.listdir(vtu) if f.endswith(".tmp")]
assert not left, f"temporary files left: {left}"
frames = [d.get("file") for d in ET.parse(os.path.join(vtu, "series.pvd")).getroot().iter("DataSet")]
on_disk = sorted(f for f in os.listdir(vtu) if f.endswith(".vtu"))
assert sorted(frames) == on_disk, f"series.pvd lists {frames}, directory has {on_disk}"
for f in frames:
    piece = ET.parse(os.path.join(vtu, f)).getroot().find("UnstructuredGrid/Piece")
    assert piece is not None and int(piece.get("NumberOfPoints")) > 0, f
print(f"ok: {rows} complete rows, {len(frames)} complete frames")
PY
}
stop_run TERM 143
stop_run INT 130

# SIGINT to the background job $pid, which must still run, end within SECONDS and exit 130.
interrupt() {  # SECONDS WHAT
  kill -0 "$pid" 2>/dev/null || fail "$2 ended before the signal"
  kill -INT "$pid"
  for _ in $(seq $(( $1 * 10 ))); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -0 "$pid" 2>/dev/null && fail "$2 still running $1 s after SIGINT"
  wait "$pid"
  local rc=$?
  pid=
  [ "$rc" -eq 130 ] || fail "$2 SIGINT: exit code $rc, wanted 130"
}
echo "ok: SIGTERM -> 143, SIGINT -> 130, output complete"

# meshing: a signal kills TetGen's process at once (a 300 x 300 torus meshes for about a
# minute here) and `run` exits 130 having written nothing.
"$exe" run --scene "$data/surface.toml" --set 'body.shape="torus"' 'body.segments=[300,300]' mesh.cache=false \
  --csv "$tmp/m.csv" >"$tmp/out.txt" 2>"$tmp/err.txt" &
pid=$!
sleep 2
interrupt 3 meshing
grep -q "stopped by signal 2 .*meshing stopped" "$tmp/err.txt" || fail "meshing: no stop message"
[ ! -e "$tmp/m.csv" ] || fail "a CSV was written although meshing was stopped"
echo "ok: meshing stopped within 3 s of SIGINT, nothing written"

# accuracy: a signal stops the run in progress between its steps (the coarse reference at
# lambda 0.001 is millions of steps: minutes; it starts in well under 2 s, also under the
# sanitizers), exit 130, and that run gives no row: an earlier result in --out is kept.
if [ -n "$torus" ]; then
  mkdir -p "$tmp/acc" && echo "earlier result" >"$tmp/acc/accuracy.csv" && echo "earlier table" >"$tmp/acc/accuracy.md"
  "$exe" accuracy --scene "$torus" --backend cpu --out "$tmp/acc" --levels 45x9 --ref 45x9 --ref-lambda 0.001 \
    --lambdas 1 --precisions float --elements T4 --t-end 0.2 >"$tmp/out.txt" 2>"$tmp/err.txt" &
  pid=$!
  for _ in $(seq 300); do grep -q "\[1/" "$tmp/err.txt" 2>/dev/null && break; sleep 0.1; done
  sleep 2
  interrupt 3 accuracy
  grep -q "stopped by signal 2 after 0 of .*; wrote nothing" "$tmp/err.txt" || fail "accuracy: no stop message naming 0 runs"
  [ "$(cat "$tmp/acc/accuracy.csv")" = "earlier result" ] && [ "$(cat "$tmp/acc/accuracy.md")" = "earlier table" ] ||
    fail "accuracy changed the earlier result before it had a row"
  echo "ok: accuracy stopped within 3 s of SIGINT, no row for the run in progress, the earlier result kept"
fi

# bench: a signal stops a long timed sample within about half a second (its pieces), not
# after the sample (--steps 1e8 in 3 samples: minutes each), and writes nothing.
"$exe" bench --scene "$data/surface.toml" --steps 100000000 --samples 3 --json "$tmp/b.json" >"$tmp/out.txt" \
  2>"$tmp/err.txt" &
pid=$!
sleep 3
t0=$(date +%s)
interrupt 10 bench
grep -q "stopped by signal 2 before the benchmark finished; wrote nothing" "$tmp/err.txt" || fail "bench: no stop message"
[ ! -e "$tmp/b.json" ] || fail "bench wrote $tmp/b.json although stopped"
echo "ok: bench stopped within $(( $(date +%s) - t0 )) s of SIGINT, nothing written"

# An output FIFO with no reader: the run waits up to 5 s for one; a signal ends that wait at
# once and reads as the stop it is (exit 130), not as "no reader" (exit 5).
# An earlier VTU series in --vtu stays whole: the FIFO is opened before the first frame,
# which would replace it.
rm -rf "$tmp/fv"
"$exe" run --scene "$data/surface.toml" --vtu "$tmp/fv" >/dev/null 2>&1 || fail "FIFO: the earlier series was not written"
series=$(md5sum <"$tmp/fv/series.pvd")
mkfifo "$tmp/fifo.csv"
"$exe" run --scene "$data/surface.toml" --csv "$tmp/fifo.csv" --vtu "$tmp/fv" >"$tmp/out.txt" 2>"$tmp/err.txt" &
pid=$!
sleep 1
interrupt 1 "waiting for a FIFO's reader"
grep -q "stopped by signal 2 (.*stopped while waiting for the FIFO's reader)" "$tmp/err.txt" || fail "FIFO: no stop message"
[ "$(md5sum <"$tmp/fv/series.pvd")" = "$series" ] || fail "FIFO: the earlier VTU series was replaced"
echo "ok: the wait for a FIFO's reader stopped within 1 s of SIGINT, the earlier series kept"

#!/usr/bin/env bash
# adaptive_stop.sh SOFTTLED DATA ASSETS
# Signals answered between steps, not at output times: with time.dt = "adaptive" and a
# tiny dt_max one output interval takes minutes, yet SIGTERM / SIGINT / SIGHUP end the run
# within a few seconds (pipelined and --sync-checks loops) with exit 143 / 130 / 129, the
# "stopped by signal" message and only complete CSV rows at output times. The long-run
# warning comes within the first interval (adaptive, and a fixed step of ~1e-11 s from
# material.rho = 1e-9). A fixed step stops between steps inside a long output interval. bench and accuracy stop on SIGINT / SIGHUP with the message.
set -u
exe=$1 data=$2 assets=$3
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
status=0
fail() { echo "FAIL: $*"; echo "--- stderr"; cat "$tmp/err.txt"; status=1; }

# start CMD...: in the background, stderr to err.txt
start() { rm -f "$tmp/err.txt" "$tmp/out.csv"; "$@" >"$tmp/out.txt" 2>"$tmp/err.txt" & pid=$!; }
# wait_for FRAGMENT SECONDS
wait_for() {
  for _ in $(seq $(($2 * 10))); do
    grep -qF -- "$1" "$tmp/err.txt" 2>/dev/null && return 0
    kill -0 "$pid" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
# stop SIGNAL WANT MAXSECONDS: the exit code and how fast it came
stop() {
  local t0 rc
  t0=$(date +%s%N)
  kill -"$1" "$pid"
  wait "$pid"; rc=$?; pid=
  local ms=$((($(date +%s%N) - t0) / 1000000))
  [ "$rc" -eq "$2" ] || fail "SIG$1: exit $rc, wanted $2"
  [ "$ms" -le $(($3 * 1000)) ] || fail "SIG$1: answered after $ms ms (at most $3 s)"
  grep -q "softtled: stopped by signal" "$tmp/err.txt" || fail "SIG$1: no 'stopped by signal' message"
}
csv_ok() {  # every row complete, at output times (multiples of 0.001 s), count as reported
  local rows
  rows=$(sed -n 's/.*wrote \([0-9]*\) CSV rows to.*/\1/p' "$tmp/err.txt")
  python3 - "$tmp/out.csv" "${rows:-x}" <<'PY' || fail "incomplete CSV"
import sys
data = open(sys.argv[1]).read()
assert data.endswith("\n"), "no final newline"
lines = data.splitlines()
n = len(lines[0].split(","))
for l in lines[1:]:
    f = l.split(","); assert len(f) == n, l
    t = float(f[0]); assert abs(t / 0.001 - round(t / 0.001)) < 1e-6, f"row off the output times: t = {t}"
assert sys.argv[2] == str(len(lines) - 1), f"{len(lines) - 1} rows, reported {sys.argv[2]}"
PY
}
scene=$assets/scenes/torus_coarse.toml
adaptive=(--set time.dt=adaptive time.dt_max=1e-9 time.output_every=0.001)
for mode in pipelined sync; do
  extra=(); [ $mode = sync ] && extra=(--sync-checks)
  for sig in TERM:143 INT:130 HUP:129; do
    start "$exe" run --scene "$scene" "${adaptive[@]}" "${extra[@]}" --csv "$tmp/out.csv"
    wait_for "warning: this run will take about" 30 || fail "$mode: no long-run warning within the first interval"
    stop "${sig%%:*}" "${sig##*:}" 5
    csv_ok
  done
done
# A fixed step of ~1e-11 s (material.rho = 1e-9): the warning within the first interval too.
start "$exe" run --scene "$data/surface.toml" --set material.rho=1e-9 time.duration=1 --csv "$tmp/out.csv"
wait_for "warning: this run will take about" 30 || fail "fixed tiny dt: no long-run warning"
stop TERM 143 5
# A fixed step whose one output interval is 1.8 million steps (the paper's torus, 10 s on
# the CPU: minutes), so the signal comes inside it: answered between steps (after the
# first, then every Simulation::kStopCheckSteps = 1000 or about 0.1 s), not at its end,
# within a second; the CSV keeps only the row at t = 0.
start "$exe" run --scene "$assets/scenes/torus_drop.toml" --backend cpu --set time.output_every=10 time.duration=10 --csv "$tmp/out.csv"
wait_for "backend cpu" 120 || fail "fixed step: no start line"; sleep 2
stop TERM 143 2
t=$(sed -n 's/.*stopped by signal 15 at t = \([0-9.]*\) s.*/\1/p' "$tmp/err.txt")
python3 - "$t" "$tmp/out.csv" <<'PY' || fail "fixed step: not stopped between steps inside an output interval"
import sys
t, dt, every = float(sys.argv[1]), 5.56267e-6, 10
steps = t / dt
assert abs(steps - round(steps)) < 0.05, f"t = {t}: {steps} steps, not a whole number"
assert 0 < steps < every / dt - 1, f"t = {t}: not inside the first output interval (stopped at its end)"
rows = open(sys.argv[2]).read().splitlines()[1:]
assert len(rows) == 1 + int(t / every), f"{len(rows)} rows at t = {t}"
PY
# bench and accuracy: the handler is installed, the usual message, 130 / 129.
start "$exe" bench --scene "$data/surface.toml" --steps 1000000000 --samples 1000
sleep 2; stop INT 130 20
start "$exe" bench --scene "$data/surface.toml" --steps 1000000000 --samples 1000
sleep 2; stop HUP 129 20
rm -rf "$tmp/acc"
start "$exe" accuracy --scene "$assets/scenes/torus_drop.toml" --ref 12x5 --levels 10x4 --lambdas 0.5,0.4,0.3,0.25,0.2,0.1 \
  --precisions float --elements T4 --t-end 10 --out "$tmp/acc"
wait_for "[3/8]" 120 || fail "accuracy: no third run"
stop INT 130 60
rows=$(sed -n 's/.*wrote \([0-9]*\) rows to.*/\1/p' "$tmp/err.txt")
[ -n "$rows" ] && [ "$((rows + 1))" -eq "$(wc -l <"$tmp/acc/accuracy.csv")" ] && [ "$(tail -c1 "$tmp/acc/accuracy.csv" | od -An -c | tr -d ' ')" = '\n' ] &&
  [ "$(grep -c '^| 1' "$tmp/acc/accuracy.md")" -eq "$rows" ] || fail "accuracy: rows written ($rows) do not match the files"
[ $status -eq 0 ] && echo "ok: adaptive runs stop within seconds (TERM/INT/HUP, both loops), warnings in the first interval, bench/accuracy stop"
exit $status
